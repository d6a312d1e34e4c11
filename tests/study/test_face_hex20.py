"""The QUAD8-face table (:mod:`infsup_contact.study.face.hex20`): β_h, kernels and verdicts of the
spaces on HEX20 bodies, computed, and its command's one-line refusals."""
import pytest

from infsup_contact.errors import InputError
from infsup_contact.study.face.hex20 import COLUMNS, hex20_table, main, quad8_cases


def test_the_table_gives_every_column_and_the_verdicts_of_the_proofs():
    rows = hex20_table(ns=(4, 6, 8), cases=["Q8", "T5", "LIN0-Q8"], norms=("H",))
    assert all(tuple(r) == COLUMNS for r in rows) and len(rows) == 9
    assert all(r["kernel_dim"] == r["structural_kernel_dim"] for r in rows)
    verdict = {r["case"]: r["verdict"] for r in rows}
    # Q8 and LIN0-Q8: no kernel, β_H on a plateau; T5: the four corner modes a ⊗ b on every N
    assert verdict == {"Q8": "STABLE", "T5": "UNSTABLE", "LIN0-Q8": "STABLE"}
    assert all(r["kernel_dim"] == 4 for r in rows if r["case"] == "T5")


def test_every_quad8_space_is_listed_once():
    cases = quad8_cases()
    assert len(cases) == len(set(cases)) and {"Q8", "Q8-ALL", "TDUAL-Q8", "DISC-P1", "LIN0-Q8", "T4"} <= set(cases)
    assert "DUAL-Q9" not in cases and "DUAL-Q8" not in cases


def test_bad_requests_are_refused_in_one_line(capsys):
    assert main(["--N", "4", "6"]) == 2
    assert main(["--case", "DUAL-Q9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "--N" in err[0] and "--case" in err[1], err
    with pytest.raises(InputError, match="N"):
        hex20_table(ns=(1, 2, 3))
