"""Figure 5 data: a stable and an unstable pair solved on the same mesh (membranes scene).

Writes results/tables/gamma_profiles.csv (case,k,N,x,quantity,value; quantity in gap,
lambda, u1, u2) and results/tables/field_values.csv (case,k,N,side,x,y,u at the mesh
vertices). All logic is in :func:`infsup_contact.study.contact.profiles.contact_profiles`.
"""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.contact.profiles import contact_profiles  # noqa: E402
from infsup_contact.study.contact.scenes import scene as make_scene  # noqa: E402

p = snakemake.params  # noqa: F821
spec = p.scene_spec
kind, scene_params = spec["kind"], {key: v for key, v in spec.items() if key not in ("kind", "N")}
c1, c2 = p.c
sc = make_scene(kind, c1=c1, c2=c2, **scene_params)
gamma, field = contact_profiles(p.cases, p.k, p.N, scene=sc, family=p.family, per_interval=p.per_interval)
cfg = dict(cases=list(p.cases), k=p.k, N=p.N, family=p.family, scene=spec, c=list(p.c),
           per_interval=p.per_interval)
write_csv_atomic(snakemake.output.gamma, add_provenance(gamma, cfg))  # noqa: F821
write_csv_atomic(snakemake.output.field, add_provenance(field, cfg))  # noqa: F821
print(gamma.groupby(["case", "quantity"]).value.agg(["min", "max"]).to_string(), file=sys.stderr)
