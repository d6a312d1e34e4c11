"""Checks of a foreign producer's export (examples/producers/): shared by its test files.

Each producer runs in its own interpreter; these helpers run it as a subprocess, read what
it wrote, and check it against what follows from the mathematics, by routes of our own:
the multiplier basis its manifest describes (built with ``make_space``, the L² mass by
``gram_l2``), body traces on Γ as piecewise P_k on the body's Γ nodes, and exact
integrals on the union of the partitions (Gauss-Legendre, exact for the polynomial degree).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import scipy.io
import yaml

from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.segment.norms import gram_l2

ROOT = Path(__file__).resolve().parents[2]
EPS = np.finfo(float).eps
ROUNDOFF = 64 * EPS
"""Bound on the relative round-off of an assembled entry or a short sum of them: an entry is a
sum of at most a few quadrature products (≤ 3 points on a segment for k + s ≤ 4), a row of
B v or of the Gauss sums below at most ~20 such terms; 64 ε covers both with margin."""


def run_export(python, script: Path, out: Path, space: str, ns, offset: int = 0, timeout: int = 600):
    """Run ``script`` with ``python`` as the contract says; the manifest's path. Asserts exit 0
    and no stdout (the contract: no other output)."""
    cmd = [str(python), str(script), "--out", str(out), "--space", space, "--N", *map(str, ns)]
    if offset:
        cmd += ["--offset", str(offset)]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=_env())
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout == "", res.stdout[:500]
    return out / "levels.yaml"


def run_cli(python, script: Path, *args, timeout: int = 120):
    """Run the exporter with raw arguments: (exit code, stdout, stderr)."""
    res = subprocess.run([str(python), str(script), *map(str, args)], capture_output=True, text=True,
                         timeout=timeout, env=_env())
    return res.returncode, res.stdout, res.stderr


def _env():
    import os

    env = dict(os.environ)
    env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    return env


_COORDS = {}


def body_coordinates(python, script: Path, n: int, space: str, offset: int = 0, ns=None):
    """(coordinates of A's dofs in A's order, number of Ω1's dofs: A's first block), from the
    producer's own ``assemble_level`` run in its interpreter; one run for every N of ``ns``
    (default: n alone), kept for later calls."""
    key = (str(script), space, offset)
    ns = tuple(ns or (n,))
    if (key, n) not in _COORDS:
        code = ("import sys, json; sys.path.insert(0, {d!r}); import export; out = []\n"
                "for n in {ns!r}:\n"
                "    lv = export.assemble_level(n, {s!r}{o}); out.append([lv['coords'].tolist(), int(lv['n1'])])\n"
                "print(json.dumps(out))").format(d=str(script.parent), ns=ns, s=space, o=f", {offset}" if offset else "")
        res = subprocess.run([str(python), "-c", code], capture_output=True, text=True, timeout=600, env=_env())
        assert res.returncode == 0, res.stderr[-2000:]
        for m, (coords, n1) in zip(ns, json.loads(res.stdout.strip().splitlines()[-1])):
            _COORDS[key, m] = (np.asarray(coords)[:, :2], n1)
    return _COORDS[key, n]


def read_level(manifest: Path, i: int):
    """(entry, A, B, G) of level i, matrices as scipy CSR."""
    data = yaml.safe_load(manifest.read_text())
    lv = data["levels"][i]
    mats = [scipy.io.mmread(manifest.parent / lv[key]).tocsr() for key in ("A", "B", "G")]
    return (lv, *mats)


def described_space(desc: dict):
    """The SegmentSpace the manifest's helper form describes, and ``rows`` (row of B of
    the j-th basis function left to right)."""
    bp = np.asarray(desc["breakpoints"], float)
    if desc["basis"] == "lagrange":
        space = make_space(bp, desc["degree"], True, desc.get("ends", "keep") == "drop")
    elif desc["basis"] == "discontinuous":
        space = make_space(bp, desc["degree"], False, False)
    else:
        raise ValueError(f"no check for basis {desc['basis']!r}")
    rows = np.asarray(desc.get("rows", range(space.dim)), int)
    assert rows.shape == (space.dim,) and len(set(rows.tolist())) == space.dim
    return space, rows


def mass_mismatch(G, desc, constrained=()) -> float:
    """max |G[rows, rows] − L² mass of the described basis| / max |G|, over the described
    functions whose row of B is not in ``constrained`` (a dirichletbc's unit rows of G)."""
    space, rows = described_space(desc)
    M = gram_l2(space)
    j = np.flatnonzero(~np.isin(rows, np.asarray(constrained, int)))
    Gd = G.toarray()[np.ix_(rows[j], rows[j])]
    return float(np.abs(Gd - M[np.ix_(j, j)]).max() / np.abs(G).max())


def constrained_rows(B, G) -> np.ndarray:
    """Rows of a dirichletbc on the multipliers: B's row zero, G's row a unit row."""
    Bd, Gd = B.toarray(), G.toarray()
    return np.array([r for r in range(Bd.shape[0]) if not Bd[r].any() and Gd[r, r] == 1.0
                     and np.count_nonzero(Gd[r]) == 1], int)


def trace_space(coords: np.ndarray, cols: np.ndarray, k: int):
    """A body's trace on Γ: the P_k space on the partition of its Γ nodes, and for each of
    the given columns of A (dofs on Γ) its basis index there."""
    x = coords[cols, 0]
    bp = np.unique(np.round(x, 14))[::k]  # P_k on a segment: every k-th Γ node is a vertex
    space = make_space(bp, k, True, False)
    nodes = space.nodes()
    index = np.array([int(np.argmin(np.abs(nodes - xi))) for xi in x])
    assert np.allclose(nodes[index], x, atol=1e-12), "Γ nodes of the body not on a P_k lattice"
    return space, index


def gauss_on_union(*breakpoints, points: int = 6):
    """Gauss-Legendre points and weights on every interval of the union of the partitions
    (exact for polynomials of degree 2·points − 1 on each piece)."""
    bp = np.unique(np.round(np.concatenate(breakpoints), 14))
    t, w = np.polynomial.legendre.leggauss(points)
    a, b = bp[:-1, None], bp[1:, None]
    x = (a + b) / 2 + (b - a) / 2 * t[None, :]
    return x.ravel(), ((b - a) / 2 * w[None, :]).ravel()


def exact_coupling(desc, coords, n1: int, k: int, gamma_y: float = 1.0):
    """The exact mortar coupling [−B1 | B2] of the described multipliers against the bodies'
    Γ traces (A's columns; columns off Γ are 0), and the mask of the Γ columns.
    ∫_Γ μ_i φ_j on the union of the three partitions (multipliers, Ω1's, Ω2's Γ nodes)."""
    space, rows = described_space(desc)
    on_gamma = np.isclose(coords[:, 1], gamma_y)
    body = np.r_[np.zeros(n1, int), np.ones(len(coords) - n1, int)]
    out = np.zeros((space.dim, len(coords)))
    traces = []
    for side, sign in ((0, -1.0), (1, 1.0)):
        cols = np.where(on_gamma & (body == side))[0]
        tspace, index = trace_space(coords, cols, k)
        traces.append((cols, tspace, index, sign))
    x, w = gauss_on_union(space.breakpoints, *(t[1].breakpoints for t in traces))
    mu = space.evaluate(x)  # (points, dim): basis j left to right
    for cols, tspace, index, sign in traces:
        phi = tspace.evaluate(x)[:, index]
        out[:, cols] = sign * (mu * w[:, None]).T @ phi
    B = np.zeros((int(rows.max()) + 1, len(coords)))
    B[rows] = out
    return B, on_gamma


def check_spd(A) -> None:
    """A symmetric (to round-off) and positive definite (a Cholesky factorization exists)."""
    Ad = A.toarray()
    asym = np.abs(Ad - Ad.T).max()
    assert asym <= ROUNDOFF * np.abs(Ad).max(), f"A not symmetric: {asym:.3g}"
    np.linalg.cholesky((Ad + Ad.T) / 2)  # raises LinAlgError if not SPD


def strip_manifest(manifest: Path, norm: str) -> Path:
    """A copy of the manifest with ``norm`` set and the ``norm: H`` keys (``gamma``, per level
    ``multipliers`` and ``traces``) removed: the form the certifier reads before ``norm: H``."""
    data = yaml.safe_load(manifest.read_text())
    data["norm"] = norm
    data.pop("gamma", None)
    for lv in data["levels"]:
        lv.pop("multipliers", None)
        lv.pop("traces", None)
    out = manifest.with_name(f"levels-{norm}.yaml")
    out.write_text(yaml.safe_dump(data, sort_keys=False))
    return out


def verdict_row(manifest: Path, *extra):
    """``infsup-contact verdict --system`` in this process: (exit code, the CSV row as a dict, stderr)."""
    import csv
    import io

    from helpers.cli import run_in_process

    code, out, err = run_in_process(["verdict", "--system", str(manifest), *extra])
    rows = list(csv.DictReader(io.StringIO(out)))
    return code, (rows[0] if rows else None), err


def beta_rows(manifest: Path):
    """``infsup-contact beta --system`` rows (one per level) as dicts."""
    import csv
    import io

    from helpers.cli import run_in_process

    code, out, err = run_in_process(["beta", "--system", str(manifest)])
    assert code == 0, err[-2000:]
    return list(csv.DictReader(io.StringIO(out)))


def suite_beta(case: str, k: int, n1: int, n2: int, norm: str = "L2") -> dict:
    """``infsup-contact beta --case`` on the suite's structured meshes: the row as a dict."""
    import csv
    import io

    from helpers.cli import run_in_process

    code, out, err = run_in_process(["beta", "--case", case, "--k", str(k), "--N1", str(n1), "--N2", str(n2),
                                     "--norm", norm])
    assert code == 0, err[-2000:]
    return next(csv.DictReader(io.StringIO(out)))


def python_has(python, module: str) -> bool:
    """Whether ``python`` exists and imports ``module``."""
    if not Path(python).exists():
        return False
    res = subprocess.run([str(python), "-c", f"import {module}"], capture_output=True, timeout=120)
    return res.returncode == 0


__all__ = [n for n in dir(sys.modules[__name__]) if not n.startswith("_")]


def check_refused(python, script, tmp_path, args, names) -> None:
    """The exporter run with a bad command line (``OUT``: a new directory, ``FILE``: a file, both
    in ``tmp_path``): exit 2, nothing on stdout, one line on stderr naming ``names``, nothing
    written."""
    (tmp_path / "FILE").write_text("not a directory")
    args = [str(tmp_path / a) if a in ("OUT", "FILE") else a for a in args]
    code, out, err = run_cli(python, script, *args)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and names in err, err
    assert not (tmp_path / "OUT").exists()


def load_script(path, name: str):
    """A producer's module (``examples/producers/<code>/export.py``) imported under its own ``name``:
    every producer's script is called ``export``, so ``import export`` in two test modules of one
    worker returns whichever came first. Its folder goes on ``sys.path`` for its sibling modules."""
    import importlib.util
    import sys

    if name in sys.modules:
        return sys.modules[name]
    folder = str(Path(path).parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def export_once(tmp_path_factory, python, script: Path, ns):
    """``get(space, offset=0)``: the manifest of one space and offset on ``ns``, exported by
    :func:`run_export` once per (space, offset) and reused (the producers' tests' module fixture)."""
    done = {}

    def get(space, offset=0):
        if (space, offset) not in done:
            done[space, offset] = run_export(python, script, tmp_path_factory.mktemp(f"{space}-{offset}"), space, ns,
                                             offset)
        return done[space, offset]
    return get
