"""The α sweep on the QUAD8 faces of HEX20 bodies (study/face/alpha.py ``--bodies hex20``): at Popp's
α = 1/5 it is the registered TDUAL-Q8 on the same bodies (two routes: the sweep's unregistered spec and
the registry's entry), the α that make a corner weight ≤ 0 are refused, and bad flags are one line."""
from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest



from infsup_contact.models import MODELS
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions
from infsup_contact.study.face import alpha


def test_popp_alpha_on_hex20_is_the_registered_tdual_q8():
    rows = pd.DataFrame(alpha.sweep(ns=(4,), alphas=(0.1, 0.2), elements=("QUAD8",), norms=("H",), cell="hex20"))
    assert not rows[rows.alpha == 0.1].accepted.any()  # corner weight (8α − 1)/3 < 0
    at_popp = rows[rows.alpha == 0.2].iloc[0]
    registered = beta_rows("structured", 2, 4, 4, ["TDUAL-Q8"], norms=("H",), model=MODELS["membranes3d"],
                           mesh=MeshOptions(element="hex20"))[0]
    assert np.isclose(at_popp.beta, registered["beta"], rtol=1e-10, atol=0)


def test_the_command_runs_on_hex20_bodies(capsys):
    assert alpha.main(["--N", "4", "--element", "QUAD8", "--bodies", "hex20"]) == 0
    table = pd.read_csv(io.StringIO(capsys.readouterr().out))
    assert (table.N == 4).all() and table.beta.notna().any()


@pytest.mark.parametrize("argv, key", [(["--bodies", "brick"], "element"),
                                       (["--bodies", "hex20", "--element", "QUAD9"], "element")])
def test_bad_bodies_are_one_line(argv, key, capsys):
    assert alpha.main(["--N", "4", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and key in err
