"""The same verdicts on every CPU: the kernel and verdict tests, the 3D kernel tests and a small
β sweep (the segment's and a face's) under each machine path of study/machines/paths.py — OpenBLAS's
core types and MKL's code branches. A path this CPU cannot take is skipped with the reason (its
missing flags, or MKL's branch on another vendor); the README says which ones CI covered.

MKL's switch is MKL_CBWR (measured, machines.py's docstring): its branch is read back
(``MKL_CBWR_Get``) and the digits of a PARDISO Schur complement differ between the default,
AUTO and COMPATIBLE branches — the evidence MKL's path took effect, as OpenBLAS's core name is
for its core type."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from helpers.once import once

from infsup_contact.errors import InputError
from infsup_contact.table_schemas import SCHEMAS
from infsup_contact.study.machines import agreement, ledgers, paths as machines

ROOT = Path(__file__).resolve().parents[2]
PATHS = [pytest.param(p.name, id=p.wildcard) for p in machines.PATHS]
UNIT_TESTS = ["tests/solvers/test_kernel.py", "tests/solvers/test_kernel_gap.py", "tests/cli/test_verdict.py",
              # the numerical tests; bad input and exit codes do not touch BLAS
              "-k", "not bad_input and not exit_code and not cli_ and not example_space"]
FACE_TESTS = [
    # kernels on the face against the dimension count and 1D ranks (hexahedra; tetrahedra, k = 1)
    "tests/discretization/face/test_face_beta.py::test_kernel_is_the_dimension_count",
    "tests/discretization/face/test_face_beta.py::test_tetrahedra[2-2-1]",
    "tests/discretization/face/test_face_beta.py::test_beta_agrees_with_the_saddle_point_pencil",
    "tests/discretization/face/test_face_beta.py::test_verdict_for_the_3d_model",
    # the Schur routes, PARDISO's among them, against each other and dense elimination
    "tests/discretization/face/test_face_beta.py::test_every_schur_route_agrees_in_3d",
    "tests/discretization/face/test_face_beta.py::test_auto_route_takes_pardiso_on_a_face_and_superlu_on_the_segment",
    "tests/discretization/face/test_face_beta.py::test_pardiso_schur_on_small_matrices_equals_dense_elimination",
    "tests/la/test_pardiso_schur_factor.py",
    # elastic3d: six rigid modes, its kernels = the count = the membranes'
    "tests/models/test_elastic3d.py::test_floating_body_has_exactly_the_six_rigid_modes",
    "tests/models/test_elastic3d.py::test_schur_is_spd_and_equals_the_reference_routes",
    "tests/models/test_elastic3d.py::test_kernels_on_matching_meshes_are_the_dimension_count",
    "tests/models/test_elastic3d.py::test_elastic_and_membranes_share_kernels_and_both_are_stable_for_t3",
    "tests/models/test_elastic3d.py::test_non_matching_kernels_equal_the_membranes",
]
"""The 3D kernel tests run under every path (~10 s each): those that decide kernel dimensions on
the face or go through PARDISO. Left out: the larger tetrahedra (35 s), the 3D families (16 s),
the CLI and bad-input tests, and the face claims' tests (synthetic tables, no BLAS)."""


def _env(name):
    return machines.machine_env(name, dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1"))


def _skip_unless_runnable(name):
    ok, why = machines.runnable(name)
    if not ok:
        pytest.skip(why)


def _pytest_under(name, args):
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-o", "addopts=", *args],
                         cwd=ROOT, env=_env(name), capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout[-3000:]


def _sweeps(root: Path) -> dict:
    """path name → output folder (a string) of the sweep run on it, None where this CPU cannot take it."""
    out = {}
    for path in machines.PATHS:
        if not machines.runnable(path.name)[0]:
            out[path.name] = None
            continue
        folder = root / path.wildcard
        folder.mkdir()
        subprocess.run([sys.executable, "-m", "infsup_contact.study.machines.paths", str(folder)], cwd=ROOT,
                       env=_env(path.name), check=True, capture_output=True, timeout=600)
        out[path.name] = str(folder)
    return out


@pytest.fixture
def runs(tmp_path_factory):
    """path name → output folder of the sweep run on it (None when this CPU cannot take it): the
    sweeps made once per pytest run, whichever workers the tests reading them land on."""
    made = once(tmp_path_factory, "machines_runs", _sweeps)
    return {name: None if folder is None else Path(folder) for name, folder in made.items()}


def test_cpu_flags_and_vendor_decide_what_can_run():
    assert machines.runnable("openblas:SkylakeX", {"avx2", "fma"})[0] is False
    assert "avx512f" in machines.runnable("openblas:SkylakeX", {"avx2", "fma"})[1]
    assert machines.runnable("openblas-Haswell", {"avx", "avx2", "fma", "sse3"}) == (True, "")
    flags = {"avx", "avx2", "fma", "sse3", *machines.AVX512_FLAGS, "avx512cd"}
    assert machines.runnable("mkl:AVX512", flags, "GenuineIntel", mkl=True) == (True, "")
    ok, why = machines.runnable("mkl:AVX2", flags, "AuthenticAMD", mkl=True)
    assert not ok and "GenuineIntel" in why and "AuthenticAMD" in why
    assert "could not be loaded" in machines.runnable("mkl:default", flags, "GenuineIntel", mkl=False)[1]
    with pytest.raises(InputError, match="machine path.*openblas:Haswel"):
        machines.runnable("openblas:Haswel")


def test_a_path_sets_its_switch_and_drops_the_others():
    base = {"OPENBLAS_CORETYPE": "Zen", "MKL_CBWR": "AVX2", "MKL_ENABLE_INSTRUCTIONS": "AVX", "HOME": "/h"}
    assert machines.machine_env("mkl:COMPATIBLE", base) == {"MKL_CBWR": "COMPATIBLE", "HOME": "/h"}
    assert machines.machine_env("mkl-default", base) == {"HOME": "/h"}
    assert machines.machine_env("openblas:Prescott", base) == {"OPENBLAS_CORETYPE": "Prescott", "HOME": "/h"}
    names = [p.wildcard for p in machines.PATHS]
    assert len(set(names)) == len(names) and all(n.replace("-", "").isalnum() for n in names)


def _ledger(folder, kernel_dim=2, verdict="PASS", drop=None):
    """A synthetic CI ledger: every table of ledgers.LEDGER_TABLES, valid under its schema (the
    comparison reads through io's checks), with a kernel column or two."""
    for table, kind in ledgers.LEDGER_TABLES.items():
        if table == drop:
            continue
        f = folder / table
        f.parent.mkdir(parents=True, exist_ok=True)
        frame = _valid_frame(kind)
        if table.endswith("claims.csv"):
            frame = frame.assign(claim_id=["a", "b"], verdict=["PASS", verdict])
        else:
            frame = frame.assign(case=["T3", "R5.2"], kernel_dim=[0, kernel_dim], kernel_decision=["clear", "clear"],
                                 kernel_margin_decades=[5.1, 4.2])
        frame.to_csv(f, index=False)
    return folder


def _valid_frame(kind, n=2):
    """n rows of a table of ``kind``: each declared column with values of its type, distinct per row."""
    values = {"int": lambda i: i + 1, "float": lambda i: 0.5 + i, "str": lambda i: f"s{i}", "bool": lambda i: True}
    columns = SCHEMAS[kind].columns
    return pd.DataFrame({c: [values[t.rstrip("?")](i) for i in range(n)] for c, t in columns.items()})


def test_ledgers_differ_where_a_verdict_or_kernel_column_does(tmp_path):
    same = {"a": _ledger(tmp_path / "a"), "b": _ledger(tmp_path / "b")}
    summary, problems = ledgers.ledger_differences(same)
    assert problems == [] and summary.identical.all()
    assert {"verdict", "kernel_dim", "kernel_decision"} <= set(summary.column) <= set(ledgers.LEDGER_EXACT)
    assert not {"kernel_margin_decades", "beta"} & set(summary.column)  # a margin and a number: not compared
    _, problems = ledgers.ledger_differences({"a": same["a"], "c": _ledger(tmp_path / "c", kernel_dim=3)})
    assert len(problems) == len(ledgers.LEDGER_TABLES) - 1
    assert any(p.startswith("results/tables/beta.csv row 1 (") and "case R5.2" in p
               and p.endswith("kernel_dim 3 under c, 2 under a") for p in problems), problems
    _, problems = ledgers.ledger_differences({"a": same["a"], "d": _ledger(tmp_path / "d", verdict="FAIL")})
    assert problems == ["results/claims.csv row 1 (claim_id b): verdict FAIL under d, PASS under a"]
    dropped = _ledger(tmp_path / "e", drop="results/tables/membranes3d/patch.csv")
    _, problems = ledgers.ledger_differences({"a": same["a"], "e": dropped})
    assert len(problems) == 1 and problems[0].startswith("results/tables/membranes3d/patch.csv: missing under e")
    cut = _ledger(tmp_path / "f")
    (cut / "results/claims.csv").write_text((cut / "results/claims.csv").read_text()[:-3])  # a cut-off write
    _, problems = ledgers.ledger_differences({"a": same["a"], "f": cut})
    assert len(problems) == 1 and problems[0].startswith("results/claims.csv: damaged under f: ")


@pytest.mark.machines
@pytest.mark.slow_first  # a pytest run of three test files each (tests/conftest.py)
@pytest.mark.parametrize("name", PATHS)
def test_kernel_and_verdict_unit_tests_pass_under(name):
    _skip_unless_runnable(name)
    _pytest_under(name, UNIT_TESTS)


@pytest.mark.machines
@pytest.mark.slow_first
@pytest.mark.parametrize("name", PATHS)
def test_3d_kernel_tests_pass_under(name):
    _skip_unless_runnable(name)
    _pytest_under(name, FACE_TESTS)


def _probe(name):
    run = subprocess.run([sys.executable, "-m", "infsup_contact.study.machines.paths", "--probe"], cwd=ROOT,
                         env=_env(name), capture_output=True, text=True, check=True, timeout=300)
    return json.loads(run.stdout)


@pytest.mark.machines
@pytest.mark.parametrize("name", [p.name for p in machines.PATHS if p.vendor])
def test_mkl_refuses_the_branches_skipped_for_the_vendor(name):
    """The vendor rule of :func:`machines.runnable` against MKL itself: where it skips a branch,
    MKL does not take it (it runs AUTO); where the CPU is that vendor, MKL takes it."""
    path = machines.machine_path(name)
    if not machines.runnable(name, vendor=path.vendor)[0]:
        pytest.skip(machines.runnable(name, vendor=path.vendor)[1])  # the flags or MKL lack, not the vendor
    branch = _probe(name)["mkl"]["branch"]
    if machines.cpu_vendor() == path.vendor:
        assert branch == path.setting
    else:
        assert branch == "AUTO", f"MKL took {branch} on a {machines.cpu_vendor()} CPU: the vendor rule is too strict"


@pytest.mark.machines
@pytest.mark.parametrize("name", PATHS)
def test_the_path_took_effect(runs, name):
    if runs[name] is None:
        pytest.skip(machines.runnable(name)[1])
    names = json.loads((runs[name] / "openblas.json").read_text())
    assert names, "OpenBLAS core names not found"
    # OpenBLAS maps some core types onto another kernel family (Zen → Haswell, Prescott → Katmai)
    assert len(set(names.values())) == 1
    probe = json.loads((runs[name] / "mkl.json").read_text())
    assert probe["branch"] == machines.expected_mkl_branch(name)


@pytest.mark.machines  # reads the sweeps of every path (~60 s): .ci/run's machines step
def test_mkl_branches_change_the_digits_and_openblas_does_not(runs):
    """The MKL probe's digits (PARDISO's S and a solve): COMPATIBLE's differ from the default's
    (on the AMD EPYC of 2026-11 the default, AUTO and COMPATIBLE gave three distinct results;
    where AUTO's dispatch is the default's they may agree); the same on every OpenBLAS core
    type (MKL keeps its own kernels)."""
    probes = {n: json.loads((f / "mkl.json").read_text()) for n, f in runs.items() if f is not None}
    mkl = {n: p["digest"] for n, p in probes.items() if n.startswith("mkl:")}
    if not {"mkl:default", "mkl:COMPATIBLE"} <= set(mkl):
        pytest.skip("MKL's default and COMPATIBLE branches do not both run on this CPU")
    assert mkl["mkl:COMPATIBLE"] != mkl["mkl:default"], f"MKL_CBWR=COMPATIBLE changed no digit: {mkl}"
    openblas = {p["digest"] for n, p in probes.items() if n.startswith("openblas:")}
    assert openblas <= {mkl.get("mkl:default")}


@pytest.mark.machines  # reads the sweeps of every path (~60 s): .ci/run's machines step
def test_sweep_and_verdicts_identical_across_paths(runs):
    done = {n: f for n, f in runs.items() if f is not None}
    if len(done) < 2:
        pytest.skip("fewer than two machine paths run on this CPU")
    sweeps = {n: pd.read_csv(f / "sweep.csv") for n, f in done.items()}
    verdicts = {n: pd.read_csv(f / "verdicts.csv") for n, f in done.items()}
    kernels = {json.loads((f / "openblas.json").read_text())["scipy"] for f in done.values()}
    assert len(kernels) >= 2, f"every path ran the same OpenBLAS kernels ({kernels}): nothing compared"
    assert agreement.compare(sweeps, verdicts) == []
    worst, scaled = agreement.max_beta_difference(sweeps)
    assert scaled <= 1.0
    # the paper's kernels on every path: on matching meshes the dimension counts are exact
    # (R5.2 two zero modes, R5.4 one, the stable spaces none), on the union of 17:16 too
    from infsup_contact.discretization.spaces.registry import SPACES

    for frame in sweeps.values():
        seg = frame[frame.model == "membranes"]
        expected = [SPACES[c].structural_kernel(int(k), int(n)) for c, k, n in zip(seg.case, seg.k, seg.N2)]
        matching = (seg.N1 == seg.N2).to_numpy()
        assert (seg.kernel_dim.to_numpy()[matching] == [e for e, m in zip(expected, matching) if m]).all()
        assert (seg.kernel_dim == seg.structural_kernel_dim).all()
        # the face (PARDISO's Schur complements): every decision clear, the count on matching meshes
        face = frame[frame.model == "membranes3d"]
        assert len(face) and (face.kernel_decision == "clear").all()
        same = face[face.N1 == face.N2]
        assert (same.kernel_dim == same.structural_kernel_dim).all() and (same.kernel_check == "agree").all()
