"""User-defined spaces: loaded from FILE.py:FUNC, checked, registered, usable like a case id."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.spaces.user_spaces import load_user_space
from infsup_contact.errors import InputError
from infsup_contact.solvers.infsup import beta_rows

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = f"{ROOT}/examples/macro_p0.py:space"
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}

@pytest.fixture(autouse=True)
def forget_user_spaces():
    """Each test registers what it loads; the registry is left as the other tests expect it."""
    from infsup_contact.discretization.spaces import user_spaces

    before = set(SPACES)
    yield
    user_spaces.forget_since(before)


HEADER = """
import numpy as np
from infsup_contact.discretization.segment.multipliers import local_basis_space, make_space
from infsup_contact.discretization.spaces.spec import SpaceSpec
"""
MALFORMED = {
    # (build body, dimension, what the error must say)
    "wrong-dim": ("return make_space(x, k, True, True)", "lambda k, n: n * k", "dimension"),
    "non-finite": ("return local_basis_space(x, 1, np.arange(2 * (len(x) - 1)).reshape(-1, 2), "
                   "[[np.inf, 0], [0, 1]])", "None", "coefficients"),
    "dependent": ("return local_basis_space(x, 1, np.arange(2 * (len(x) - 1)).reshape(-1, 2), "
                  "[[1, 1], [2, 2]])", "None", "linearly independent"),
    "not-a-space": ("return np.eye(3)", "None", "SegmentSpace"),
}


def write_space(tmp_path, name, body, dimension):
    path = tmp_path / f"{name.replace('-', '_')}.py"
    path.write_text(HEADER + f"""
def build(k, x):
    {body}

def space():
    return SpaceSpec("USER-{name}", "user", "", build, lambda k: 1, dimension={dimension})
""")
    return f"{path}:space"


@pytest.mark.parametrize("name", list(MALFORMED))
def test_malformed_space_gets_one_error_naming_it(tmp_path, name):
    body, dimension, needle = MALFORMED[name]
    ref = write_space(tmp_path, name, body, dimension)
    with pytest.raises(InputError) as err:
        load_user_space(ref)
    assert f"USER-{name}" in str(err.value) and needle in str(err.value)
    assert f"USER-{name}" not in SPACES


def test_bad_references(tmp_path):
    for ref in ("no_colon", f"{tmp_path}/missing.py:space", "json:not_there"):
        with pytest.raises(InputError) as err:
            load_user_space(ref)
        assert err.value.key == "space"
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('boom')\n")
    with pytest.raises(InputError, match="boom"):
        load_user_space(f"{broken}:space")


def test_example_space_registers_once_and_runs():
    spec = load_user_space(EXAMPLE)
    assert load_user_space(EXAMPLE) is spec and SPACES[spec.id] is spec and spec.tag == spec.id
    rows = beta_rows("structured", 1, 8, 8, [spec.id], norms=["H"])
    assert rows[0]["dim_M"] == spec.dimension(1, 8) and rows[0]["kernel_dim"] == 0


def test_cli_space_flag_and_errors(tmp_path):
    exe = Path(sys.prefix) / "bin" / "infsup-contact"
    ok = subprocess.run([exe, "beta", "--space", EXAMPLE, "--k", "1", "--N1", "4", "--N2", "4", "--norm", "H"],
                        capture_output=True, text=True, env=ENV, cwd=tmp_path)
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.splitlines()[1].startswith("P0-2h,1,")
    body, dimension, needle = MALFORMED["dependent"]
    bad = subprocess.run([exe, "beta", "--space", write_space(tmp_path, "dependent", body, dimension), "--k", "1",
                          "--N1", "4", "--N2", "4"], capture_output=True, text=True, env=ENV, cwd=tmp_path)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    assert "USER-dependent" in bad.stderr and needle in bad.stderr
    both = subprocess.run([exe, "beta", "--space", EXAMPLE, "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4"],
                          capture_output=True, text=True, env=ENV, cwd=tmp_path)
    assert both.returncode == 2 and "--space" in both.stderr
