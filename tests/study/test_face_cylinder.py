"""The cylinder's β_h rows (study/face/cylinder.py): one row per (R, coupling, pair, case, norm) with
``beta``'s columns, R = inf the flat face's rows, bad input refused by the request's checks."""
import math

import pytest

from infsup_contact.errors import InputError
from infsup_contact.models.membranes3d import MEMBRANES3D
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions
from infsup_contact.study.face.cylinder import cylinder_rows

ROUNDOFF = 1e-12


def test_rows_cover_the_sweep_with_betas_columns():
    radii, pairs, cases, couplings = (math.inf, 2.0), ((2, 2), (2, 3)), ["T3", "R5.2"], ("exact", "projection")
    rows = cylinder_rows(radii, pairs, 1, cases, couplings)
    keys = {(r["radius"], r["coupling"], r["N1"], r["N2"], r["case"], r["norm"]) for r in rows}
    assert len(rows) == len(keys) == len(radii) * len(couplings) * len(pairs) * len(cases) * 2
    flat = beta_rows("structured", 1, 2, 3, cases, model=MEMBRANES3D, mesh=MeshOptions(element="hex"))
    assert set(flat[0]) | {"model", "element", "gamma", "radius", "coupling"} == set(rows[0])
    for f in flat:  # R = inf: the flat face's β_h, bit for bit (exact) and to round-off (projection: P = id)
        same = [r for r in rows if r["radius"] == math.inf and (r["N1"], r["N2"]) == (2, 3)
                and (r["case"], r["norm"]) == (f["case"], f["norm"])]
        assert [r["coupling"] for r in same] == ["exact", "projection"]
        assert same[0]["beta"] == f["beta"] and abs(same[1]["beta"] - f["beta"]) <= ROUNDOFF
        assert same[0]["kernel_dim"] == same[1]["kernel_dim"] == f["kernel_dim"]


@pytest.mark.parametrize("kwargs, key", [(dict(radii=(1.0,)), "radius"), (dict(couplings=("normal",)), "coupling"),
                                         (dict(k=5), "k"), (dict(cases=["NOPE"]), "case")])
def test_bad_arguments_are_refused_naming_the_key(kwargs, key):
    with pytest.raises(InputError) as e:
        cylinder_rows(**{"pairs": ((2, 3),), **kwargs})
    assert e.value.key == key
