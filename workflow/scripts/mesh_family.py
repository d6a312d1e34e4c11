"""Write every mesh pair of one family (.vol files) and its quality table."""
import os
import shutil
import sys
import tempfile

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.discretization.segment.meshes import mesh_pair, mesh_quality  # noqa: E402
from infsup_contact.discretization.gamma.mesh_series import seeds  # noqa: E402

family, ic = snakemake.wildcards.family, snakemake.params.ic  # noqa: F821
seed_list = seeds(ic) if family == "perturbed" else [None]
out_dir = snakemake.output.meshes  # noqa: F821
tmp_dir = tempfile.mkdtemp(dir=os.path.dirname(out_dir) or ".", prefix=".meshes-")
rows = []
for n1, n2 in snakemake.params.pairs:  # noqa: F821
    for seed in seed_list:
        kwargs = {} if seed is None else {"seed": seed, "alpha": ic["alpha"]}
        for side, mesh in zip((1, 2), mesh_pair(family, n1, n2, **kwargs)):
            n = (n1, n2)[side - 1]
            path = os.path.join(tmp_dir, f"omega{side}_N{n}" + ("" if seed is None else f"_seed{seed}") + ".vol")
            if not os.path.exists(path):  # Ω_i's mesh depends only on its own N (and seed)
                mesh.ngmesh.Save(path)
            rows.append(dict(family=family, N1=n1, N2=n2, side=side, seed=seed, **mesh_quality(mesh)))
shutil.rmtree(out_dir, ignore_errors=True)
os.replace(tmp_dir, out_dir)
write_csv_atomic(snakemake.output.table, add_provenance(pd.DataFrame(rows), ic))  # noqa: F821
