"""The same verdicts on every CPU: the kernel and verdict tests and a small β sweep under each
OpenBLAS core type (study/machines.py). A core type this CPU cannot execute is skipped with
the reason (its missing flags); the README says which ones CI covered."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from infsup_contact.study import machines

ROOT = Path(__file__).resolve().parents[1]
UNIT_TESTS = ["tests/test_kernel.py", "tests/test_kernel_gap.py", "tests/test_verdict.py",
              # the numerical tests; bad input and exit codes do not touch BLAS
              "-k", "not bad_input and not exit_code and not cli_ and not example_space"]


def _env(core):
    return machines.machine_env(core, dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """core type → output folder of the sweep run under it (None when it cannot run here)."""
    out = {}
    for core in machines.CORE_TYPES:
        ok, _ = machines.runnable(core)
        if not ok:
            out[core] = None
            continue
        folder = tmp_path_factory.mktemp(core)
        subprocess.run([sys.executable, "-m", "infsup_contact.study.machines", str(folder)], cwd=ROOT,
                       env=_env(core), check=True, capture_output=True, timeout=600)
        out[core] = folder
    return out


def test_cpu_flags_decide_what_can_run():
    assert machines.runnable("SkylakeX", {"avx2", "fma"})[0] is False
    assert "avx512f" in machines.runnable("SkylakeX", {"avx2", "fma"})[1]
    assert machines.runnable("Haswell", {"avx", "avx2", "fma", "sse3"}) == (True, "")


@pytest.mark.slow_first  # a pytest run of three test files each (tests/conftest.py)
@pytest.mark.parametrize("core", machines.CORE_TYPES)
def test_kernel_and_verdict_unit_tests_pass_under(core):
    ok, why = machines.runnable(core)
    if not ok:
        pytest.skip(why)
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-o", "addopts=",
                          *UNIT_TESTS], cwd=ROOT, env=_env(core), capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout[-3000:]


@pytest.mark.xdist_group("machines_runs")  # one worker makes the sweeps of ``runs`` once
@pytest.mark.parametrize("core", machines.CORE_TYPES)
def test_the_core_type_took_effect(runs, core):
    if runs[core] is None:
        pytest.skip(machines.runnable(core)[1])
    names = json.loads((runs[core] / "openblas.json").read_text())
    assert names, "OpenBLAS core names not found"
    # OpenBLAS maps some core types onto another kernel family (Zen → Haswell, Prescott → Katmai)
    assert len(set(names.values())) == 1


@pytest.mark.xdist_group("machines_runs")
def test_sweep_and_verdicts_identical_across_core_types(runs):
    done = {c: f for c, f in runs.items() if f is not None}
    if len(done) < 2:
        pytest.skip("fewer than two OpenBLAS core types run on this CPU")
    sweeps = {c: pd.read_csv(f / "sweep.csv") for c, f in done.items()}
    verdicts = {c: pd.read_csv(f / "verdicts.csv") for c, f in done.items()}
    kernels = {json.loads((f / "openblas.json").read_text())["scipy"] for f in done.values()}
    assert len(kernels) >= 2, f"every core type ran the same kernels ({kernels}): nothing compared"
    assert machines.compare(sweeps, verdicts) == []
    worst, scaled = machines.max_beta_difference(sweeps)
    assert scaled <= 1.0
    # the paper's kernels on every core type: on matching meshes the dimension counts are
    # exact (R5.2 two zero modes, R5.4 one, the stable spaces none), on the union of 17:16 too
    from infsup_contact.discretization.registry import SPACES

    for frame in sweeps.values():
        expected = [SPACES[c].structural_kernel(int(k), int(n)) for c, k, n in zip(frame.case, frame.k, frame.N2)]
        matching = (frame.N1 == frame.N2).to_numpy()
        assert (frame.kernel_dim.to_numpy()[matching] == [e for e, m in zip(expected, matching) if m]).all()
        assert (frame.kernel_dim == frame.structural_kernel_dim).all()
