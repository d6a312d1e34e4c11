"""``norm: H`` manifests: the multipliers described on Γ give the exact H^{-1/2}_00 Gram.

Acceptance: the described manifest (helper form and general form) reproduces ``beta --case X
--norm H`` to 1e-8 relative in β for every registered segment space, k = 1, 2, matching and
non-matching meshes, and for the tensor face spaces (hexahedral faces). Then the scaling of the
Gram with Γ's size (analytic: ‖1‖² = 7ζ(3)L²/π³ on (0, L); L², b³ and the β invariance), the
L² check that catches a wrong row order, and hostile descriptions (one line each)."""
from __future__ import annotations

import io

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.cli import main
from infsup_contact.discretization.spaces.registry import common_ids, space_spec
from infsup_contact.models import make_model
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.systems.export import segment_form, suite_levels, write_system
from infsup_contact.systems.levels import system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest
from infsup_contact.systems.multiplier_basis import Gamma, describe
from infsup_contact.systems.multiplier_gram import gram
from infsup_contact.systems.readers import SystemFileError
from infsup_contact.solvers.request import MeshOptions

NS = (4, 8)
RTOL = 1e-8
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
SEGMENT_CASES = [(case, k) for k in (1, 2) for case in common_ids(k)]
FACE_MODEL = make_model("membranes3d")
FACE_CASES = [(case, k) for k in (1, 2) for case in common_ids(k)]  # the tensor ones: every segment id


def _general(levels):
    """The same levels with every description in the general form (no helper)."""
    def general(form):
        if "x" in form:
            return {key: general(value) for key, value in form.items()}
        return segment_form(None, describe("m.yaml", 0, form, Gamma("segment", (1.0,))).space)
    return [(h, A, B, G, general(mult), *rest) for h, A, B, G, mult, *rest in levels]


def _manifest(tmp_path, case, k, offset, ns=NS, general=False, model=None, **kw):
    levels, norm, gamma = suite_levels(case, k, ns, offset, model=model, **kw)
    assert norm == "H" and all(len(lv) == 6 for lv in levels)
    if general:
        levels = _general(levels)
    path = write_system(tmp_path / f"{case}-{k}-{offset}-{general}", levels, "npz", case, norm=norm, gamma=gamma)
    return load_manifest(path, min_levels=1)


def _agree(row, ref):
    assert row["kernel_dim"] == ref["kernel_dim"]
    if ref["kernel_dim"] == 0:
        assert abs(row["beta"] - ref["beta"]) <= RTOL * ref["beta"]
    else:
        assert row["beta"] == ref["beta"] == 0.0
    assert abs(row["smallest_nonzero"] - ref["smallest_nonzero"]) <= RTOL * ref["smallest_nonzero"]


@pytest.mark.parametrize("general", [False, True], ids=["helper", "general"])
@pytest.mark.parametrize("offset", [0, 1, -1], ids=["matching", "N1=N2+1", "N1=N2-1"])
@pytest.mark.parametrize("case,k", SEGMENT_CASES)
def test_described_segment_reproduces_beta_case(tmp_path, case, k, offset, general):
    rows = system_rows(_manifest(tmp_path, case, k, offset, general=general), notes=io.StringIO())
    for n, row in zip(NS, rows):
        ref, = beta_rows("structured", k, n + offset, n, [case], norms=("H",))
        _agree(row, ref)
        assert row["norm"] == "H" and row["gram_rel_error"] == 0.0  # the log kernel: exact
        assert row["coupling_distance"] <= 1e-14  # the suite's B is the exact mortar coupling
        ref_l2, = beta_rows("structured", k, n + offset, n, [case], norms=("L2",))
        if ref_l2["kernel_dim"] == 0:  # the G file (the L2 mass) gives the L2 row beside it
            assert abs(row["beta_L2"] - ref_l2["beta"]) <= RTOL * ref_l2["beta"]


def test_every_registered_segment_space_is_covered():
    assert {c for c, _ in SEGMENT_CASES} == set(common_ids())
    for case, k in SEGMENT_CASES:  # the helper form where the registry says what the space is
        spec = space_spec(case)
        form = segment_form(spec, spec.build(k, np.linspace(0.0, 1.0, 5)))
        assert ("basis" in form) == (spec.lagrange is not None)


@pytest.mark.parametrize("case,multiplier_mesh", [("DUAL", "union"), ("T5", "omega1"), ("T3", "union")])
def test_perturbed_meshes(tmp_path, case, multiplier_mesh):
    """Non-uniform breakpoints (the perturbed family, the union of two traces) travel exactly: the
    described Gram is the suite's bit for bit. T3 on the union is nearly singular (β ~ 5e-6): there
    the two eigensolvers' round-off, ~ε λ_max / β in β, is the bound, not 1e-8 β."""
    from infsup_contact.systems.export import _suite_parts

    m = _manifest(tmp_path, case, 2, 1, family="perturbed", multiplier_mesh=multiplier_mesh)
    for n, row, level in zip(NS, system_rows(m, notes=io.StringIO()), m.levels):
        *_, space, segment, _ = _suite_parts(case, 2, n + 1, n, "perturbed", multiplier_mesh, None)
        d = describe(m.path, level.index, level.multipliers, m.gamma)
        assert np.array_equal(gram(d, "H")[0], segment.gram(space, "H")[0])
        ref, = beta_rows("perturbed", 2, n + 1, n, [case], multiplier_mesh=multiplier_mesh, norms=("H",))
        if ref["beta"] > 1e-4:
            _agree(row, ref)
        else:
            assert row["kernel_dim"] == ref["kernel_dim"] == 0
            assert abs(row["beta"] - ref["beta"]) <= 1e-14 / ref["beta"]


def test_described_verdict_equals_verdict_case(tmp_path):
    ns = (4, 8, 16)
    for case, expect in (("DUAL", "STABLE"), ("R5.4", "UNSTABLE")):
        out, _ = system_verdict(_manifest(tmp_path, case, 2, 0, ns), **CRITERION, notes=io.StringIO())
        from infsup_contact.study.verdict import verdict_rows

        ref = verdict_rows(case, 2, "structured", ns, "H", **CRITERION)
        assert out["verdict"] == ref["verdict"] == expect
        assert abs(out["beta_min"] - ref["beta_min"]) <= RTOL * max(ref["beta_min"], 1e-300)
        assert out["verdict_L2"] in ("STABLE", "UNSTABLE", "INCONCLUSIVE")


@pytest.mark.parametrize("case,k", FACE_CASES)
def test_described_face_reproduces_beta_case(tmp_path, case, k):
    """The tensor face spaces on hexahedral faces, N = 2, 3 (N1 = N2 + 1 at k = 1)."""
    offset = 1 if k == 1 else 0
    ns = (2, 3)
    m = _manifest(tmp_path, case, k, offset, ns, model=FACE_MODEL, mesh=MeshOptions(element="hex"))
    assert m.gamma == Gamma("rectangle", (1.0, 1.0))
    for n, row in zip(ns, system_rows(m, notes=io.StringIO())):
        ref, = beta_rows("structured", k, n + offset, n, [case], norms=("H",), model=FACE_MODEL, mesh=MeshOptions(element="hex"))
        _agree(row, ref)
        if k == 1:  # the bilinear hats of the traces described too: B is the exact coupling
            assert row["coupling_distance"] <= 1e-14
        else:
            assert np.isnan(row["coupling_distance"])


def test_face_only_and_triangle_spaces_keep_the_given_gram():
    levels, norm, gamma = suite_levels("T3", 1, (2,), model=FACE_MODEL, mesh=MeshOptions(element="tet"))
    assert norm == "given" and gamma is None and len(levels[0]) == 4


# ---------------------------------------------------------------- Γ's size: the Gram's scaling
def test_segment_gram_of_the_constant_is_analytic():
    """‖1‖²_{H^-1/2_00(0,L)} = Σ_n odd 8L/(nπ)² · L/(nπ) = 7ζ(3) L²/π³ (the constant is in R5.2; the
    Lagrange basis sums to 1), and ‖1‖²_{L²(0,L)} = L: a route independent of the scaling code."""
    zeta3 = 1.2020569031595942
    for length in (1.0, 2.0, 0.3):
        x = list(np.linspace(0.0, length, 7))
        d = describe("m.yaml", 0, {"basis": "lagrange", "degree": 2, "breakpoints": x}, Gamma("segment", (length,)))
        one = np.ones(d.m)
        assert abs(one @ gram(d, "H")[0] @ one - 7 * zeta3 * length ** 2 / np.pi ** 3) <= 1e-12 * length ** 2
        assert abs(one @ gram(d, "L2")[0] @ one - length) <= 1e-14 * length


def test_rectangle_gram_scaling_and_axis_swap():
    """Side L: G = L³ G_unit. A rectangle a × b and its transpose b × a (x and y swapped, rows
    permuted accordingly) are the same norm computed through aspect a/b and b/a."""
    fx = {"basis": "lagrange", "degree": 1, "ends": "drop"}
    d1 = describe("m.yaml", 0, {"x": dict(fx, breakpoints=[0, 0.5, 1]), "y": dict(fx, breakpoints=[0, 0.25, 0.5, 0.75, 1])},
                  Gamma("rectangle", (1.0, 1.0)))
    d3 = describe("m.yaml", 0, {"x": dict(fx, breakpoints=[0, 1.5, 3]), "y": dict(fx, breakpoints=[0, 0.75, 1.5, 2.25, 3])},
                  Gamma("rectangle", (3.0, 3.0)))
    np.testing.assert_allclose(gram(d3, "H")[0], 27.0 * gram(d1, "H")[0], rtol=1e-13, atol=0)
    np.testing.assert_allclose(gram(d3, "L2")[0], 9.0 * gram(d1, "L2")[0], rtol=1e-13, atol=0)
    a, b = 2.0, 0.5
    xa, yb = [0, 0.5, 1.0, 1.5, 2.0], [0, 0.125, 0.25, 0.375, 0.5]
    wide = describe("m.yaml", 0, {"x": dict(fx, breakpoints=xa), "y": dict(fx, breakpoints=yb)}, Gamma("rectangle", (a, b)))
    tall = describe("m.yaml", 0, {"x": dict(fx, breakpoints=yb), "y": dict(fx, breakpoints=xa)}, Gamma("rectangle", (b, a)))
    nx = ny = 3
    i, j = np.divmod(np.arange(nx * ny), ny)
    swap = j + ny * i  # row of ψ_i(x)ψ_j(y) of 'wide' in 'tall' (rows i + n_x j)
    Gw, info = gram(wide, "H", )
    Gt = gram(tall, "H")[0]
    order = np.argsort(i + nx * j)  # B rows of wide in order
    P = swap[order]
    np.testing.assert_allclose(Gt[np.ix_(P, P)], Gw, rtol=10 * max(info["nmax_rel_error"], 1e-8), atol=0)


def test_beta_invariant_under_the_scaling_a_length_change_induces(tmp_path):
    """Γ of length 2 (the bodies scaled by 2): A (2D stiffness) unchanged, B = ∫_Γ μ v doubled,
    G_H = L² G̃ and M = L M̃: β_h the same to round-off, the L2 check passing."""
    levels, norm, _ = suite_levels("T5", 2, NS, 1)
    scaled = []
    for h, A, B, G, mult, traces in levels:
        mult = dict(mult, breakpoints=[2.0 * t for t in mult["breakpoints"]])
        traces = [dict(t, breakpoints=[2.0 * x for x in t["breakpoints"]]) for t in traces]
        scaled.append((2 * h, A, 2.0 * B, 2.0 * G, mult, traces))
    def rows(name, lvls, length):
        path = write_system(tmp_path / name, lvls, "mtx", name, "H", gamma={"shape": "segment", "length": length})
        return system_rows(load_manifest(path, 1), notes=io.StringIO())
    unit, long = rows("u", levels, 1.0), rows("l", scaled, 2.0)
    for r1, r2 in zip(unit, long):
        assert abs(r1["beta"] - r2["beta"]) <= 1e-12 * r1["beta"]
        assert abs(r1["beta_L2"] * np.sqrt(2.0) - r2["beta_L2"]) <= 1e-12 * r2["beta_L2"]  # L2: B 2x, M 2x


# ---------------------------------------------------------------- the L2 check: a wrong row order
def test_a_row_order_other_than_the_description_is_refused(tmp_path):
    levels, norm, gamma = suite_levels("T3", 1, NS, 0)
    h, A, B, G, mult, _ = levels[1]
    perm = np.arange(B.shape[0])
    perm[[2, 3]] = perm[[3, 2]]
    bad = levels[:1] + [(h, A, B[perm], G[np.ix_(perm, perm)], mult)]
    m = load_manifest(write_system(tmp_path / "bad", bad, "mtx", "bad", norm, gamma=gamma), 1)
    with pytest.raises(SystemFileError, match=r"G1.mtx: differs from the L2 mass of levels\[1\].multipliers by "
                                              r"[0-9.e-]+ relative.*rows:"):
        system_rows(m, notes=io.StringIO())
    # the same permutation declared (rows: the row of B holding the j-th function) is accepted
    rows = perm.tolist()
    good = levels[:1] + [(h, A, B[perm], G[np.ix_(perm, perm)], dict(mult, rows=[rows.index(j) for j in range(len(rows))]))]
    m = load_manifest(write_system(tmp_path / "good", good, "mtx", "good", norm, gamma=gamma), 1)
    ref = system_rows(load_manifest(write_system(tmp_path / "ref", levels, "mtx", "ref", norm, gamma=gamma), 1),
                      notes=io.StringIO())
    assert abs(system_rows(m, notes=io.StringIO())[1]["beta"] - ref[1]["beta"]) <= 1e-12


def test_without_g_the_h_verdict_stands_alone_checked_by_the_traces(tmp_path):
    """No G: the traces check the description (an exact body block), and the H verdict stands
    alone; with neither G nor traces nothing checks it, and it is refused
    (test_systems_descriptions.py has the hostile cases)."""
    levels, norm, gamma = suite_levels("DUAL", 2, (4, 8, 16), 0)
    bare = [(h, A, B, None, mult, traces) for h, A, B, G, mult, traces in levels]
    m = load_manifest(write_system(tmp_path, bare, "mtx", "bare", norm, gamma=gamma))
    assert all(lv.G is None for lv in m.levels) and not list(tmp_path.glob("G*"))
    rows = system_rows(m, notes=io.StringIO())
    assert all(np.isnan(r["beta_L2"]) and r["description_check"] == "coupling" for r in rows)
    out, _ = system_verdict(m, **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "STABLE" and "verdict_L2" not in out
    m = load_manifest(write_system(tmp_path / "none", [lv[:5] for lv in bare], "mtx", "bare", norm, gamma=gamma))
    with pytest.raises(SystemFileError, match=r"needs G \(their L2 mass\) or traces"):
        system_rows(m, notes=io.StringIO())


def test_cli_export_then_verdict_system_is_stable(tmp_path, capsys):
    out = tmp_path / "dual"
    assert main(["export", "--case", "DUAL", "--k", "2", "--N", "4", "8", "16", "--out", str(out)]) == 0
    text = (out / "levels.yaml").read_text()
    assert "norm: H\ngamma: {shape: segment, length: 1.0}" in text and "basis: dual" in text
    capsys.readouterr()
    assert main(["verdict", "--system", str(out / "levels.yaml"), "--expect", "stable"]) == 0
    assert main(["verdict", "--system", str(out / "levels.yaml"), "--dry-run"]) == 0


# ---------------------------------------------------------------- hostile descriptions: one line, exit 2
def _base(tmp_path, case="T3", k=1, ns=(4,)):
    """A one-level norm: H manifest as a dict (to be spoiled) and its directory."""
    import yaml

    levels, norm, gamma = suite_levels(case, k, ns, 0)
    path = write_system(tmp_path, levels, "mtx", "base", norm, gamma=gamma)
    return yaml.safe_load(path.read_text()), path


def _spoil(tmp_path, capsys, change, match, dry=True):
    """``change(data)`` spoils the manifest; ``beta --system --dry-run`` (unless ``dry`` is False:
    found only where the Gram is factorized) and the run refuse it in one line matching ``match``
    (exit 2)."""
    import yaml

    data, path = _base(tmp_path)
    change(data, tmp_path)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    if not dry:
        assert main(["beta", "--system", str(path), "--dry-run"]) == 0
    for extra in (["--dry-run"], []) if dry else ([],):
        capsys.readouterr()
        assert main(["beta", "--system", str(path)] + extra) == 2
        err = capsys.readouterr().err
        errors = [line for line in err.splitlines() if not line.startswith("infsup-contact: note:")]
        assert len(errors) == 1 and "Traceback" not in err, err
        assert __import__("re").search(match, errors[0]), err


def _mult(data):
    return data["levels"][0]["multipliers"]


def _set(key, value):
    def change(data, tmp_path):
        _mult(data)[key] = value
    return change


def _general_form(data, tmp_path):
    mult = _mult(data)
    data["levels"][0]["multipliers"] = segment_form(None, describe("m.yaml", 0, mult, Gamma("segment", (1.0,))).space)


HOSTILE = [
    (_set("basis", "hermite"), r"levels\[0\]\.multipliers\.basis: 'hermite' is not one of lagrange, discontinuous, dual"),
    (_set("degree", 9), r"multipliers\.degree: expected an integer in 1\.\.7 for basis lagrange \(found 9\)"),
    (_set("degree", 0), r"multipliers\.degree: expected an integer in 1\.\.7"),
    (_set("degree", "1"), r"multipliers\.degree: expected an integer"),
    (_set("degree", True), r"multipliers\.degree: expected an integer"),
    (_set("breakpoints", [0, 0.5, 0.25, 0.75, 1]), r"multipliers\.breakpoints: not strictly increasing \(entries 1 and 2: 0\.5, 0\.25\)"),
    (_set("breakpoints", [0, 0.25, 0.5, 0.75]), r"multipliers\.breakpoints: runs from 0\.0 to 0\.75; it must cover"),
    (_set("breakpoints", [0.1, 0.25, 0.5, 0.75, 1]), r"it must cover Γ = \[0, 1\.0\]"),
    (_set("breakpoints", [0, "x", 1]), r"multipliers\.breakpoints: expected numbers"),
    (_set("breakpoints", [0, float("nan"), 1]), r"multipliers\.breakpoints: holds a non-finite number"),
    (_set("breakpoints", "bp.txt"), r"multipliers\.breakpoints: no such file .*bp\.txt"),
    (_set("breakpoints", None), r"multipliers\.breakpoints: missing"),
    (_set("ends", "maybe"), r"multipliers\.ends: 'maybe': expected keep or drop"),
    (_set("ends", "keep"), r"multipliers: describes m = 5 basis functions, B \(B0\.mtx\) has 3 rows"),
    (_set("rows", [0, 0, 1]), r"multipliers\.rows: expected a permutation of 0\.\.2 .*not each row once"),
    (_set("rows", [0, 1]), r"multipliers\.rows: expected a permutation of 0\.\.2 .*found 2 entries"),
    (_set("dofs", [[0, 1]]), r"multipliers\.dofs: only in the general form"),
    (_set("colour", "red"), r"multipliers: unknown key 'colour' in a segment form"),
    (lambda d, p: d["levels"][0].update(multipliers=5), r"levels\[0\]\.multipliers: expected a mapping or a \.yaml file"),
    (lambda d, p: d["levels"][0].update(multipliers="m.txt"), r"multipliers: 'm\.txt': expected an inline mapping or a \.yaml"),
    (lambda d, p: d["levels"][0].update(multipliers="m.yaml"), r"multipliers: no such file .*m\.yaml"),
    (lambda d, p: d["levels"][0].pop("multipliers"), r"levels\[0\]: missing key 'multipliers'"),
    (lambda d, p: d.pop("gamma"), r"norm: H and a level's 'multipliers' need the key 'gamma'"),
    (lambda d, p: d.update(gamma={"shape": "disc", "length": 1}), r"gamma\.shape: 'disc' is not one of segment, rectangle"),
    (lambda d, p: d.update(gamma={"shape": "segment", "length": -1}), r"gamma\.length: expected a finite number > 0"),
    (lambda d, p: d.update(gamma={"shape": "segment", "size": [1, 1]}), r"gamma: unknown key 'size' for a segment"),
    (lambda d, p: d.update(gamma={"shape": "rectangle", "size": [1]}), r"gamma\.size: expected \[a, b\]"),
    (lambda d, p: d.update(gamma={"shape": "rectangle", "size": [1, 1]}), r"multipliers: unknown key 'basis' in a rectangle"),
    (lambda d, p: [d["levels"][0].pop("multipliers"), d["levels"][0].pop("traces"), d.update(norm="L2")],
     r"gamma: no level describes its multipliers"),
    (lambda d, p: [d.pop("gamma"), d.update(norm="L2")], r"norm: H and a level's 'multipliers' need the key 'gamma'"),
    (lambda d, p: [d["levels"][0].pop("multipliers"), d.update(norm="L2")],
     r"levels\[0\]\.traces: only with levels\[0\]\.multipliers"),
    (lambda d, p: d["levels"][0].update(G="nothere.mtx"), r"nothere\.mtx"),
    (lambda d, p: [_general_form(d, p), _mult(d).update(dofs=[[0, 1]] * 3)],
     r"multipliers\.dofs: expected an integer array of shape \(N, s \+ 1\) = \(4, 2\)"),
    (lambda d, p: [_general_form(d, p), _mult(d).update(dofs=[[0, 1], [1], [2, 3], [3, 4]])], r"multipliers\.dofs: expected integers"),
    (lambda d, p: [_general_form(d, p), _mult(d).update(coefficients=[[1, 0, 0]])], r"multipliers\.coefficients: expected finite"),
    (lambda d, p: [_general_form(d, p), _mult(d).update(rows=[0, 1, 2])], r"multipliers\.rows: only with a helper form"),
    (lambda d, p: [_general_form(d, p), _mult(d).update(coefficients=[[0, 0], [0, 0]])],
     r"multipliers\.coefficients: basis function 0 \(row 0 of B\) is zero on every interval"),
]


def test_an_l2_mass_of_another_basis_is_refused_under_norm_l2(tmp_path, capsys):
    """norm: L2 with a description: G (the L2 mass of T3's P_1) against P_0 on 3 cells (m = 3 too)."""
    def change(d, p):
        d.update(norm="L2")
        d["levels"][0].pop("traces")
        d["levels"][0]["multipliers"] = {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 1 / 3, 2 / 3, 1]}
    _spoil(tmp_path, capsys, change, r"G0\.mtx: differs from the L2 mass of levels\[0\]\.multipliers by", dry=False)


def test_a_linearly_dependent_basis_is_refused_where_its_gram_is_factorized(tmp_path, capsys):
    """Discontinuous P_1 with both local functions L_0: every interval's pair is one function."""
    def change(d, p):
        d["levels"][0].pop("G")
        d["levels"][0]["multipliers"] = {"breakpoints": [0, 0.5, 1], "degree": 1, "dofs": [[0, 1], [2, -1]],
                                         "coefficients": [[1, 0], [1, 0]]}
    _spoil(tmp_path, capsys, change, r"levels\.yaml: levels\[0\]\.multipliers: the described basis functions are linearly dependent", dry=False)


@pytest.mark.parametrize("change,match", HOSTILE, ids=[f"{i}" for i in range(len(HOSTILE))])
def test_hostile_descriptions_are_refused_in_one_line(tmp_path, capsys, change, match):
    _spoil(tmp_path, capsys, change, match)


def test_files_cut_short_or_forged(tmp_path, capsys):
    """A .txt cut inside its last number (no final newline), an .npy whose header declares 1e9
    intervals the file does not hold, a .yaml description cut mid-list: each one line."""
    def txt(d, p):
        (p / "bp.txt").write_text("0 0.25 0.5 0.75 1")  # no final newline: its last number may be cut
        _mult(d)["breakpoints"] = "bp.txt"
    _spoil(tmp_path / "t", capsys, txt, r"bp\.txt: levels\[0\]\.multipliers\.breakpoints: the file does not end with a newline")

    def npy(d, p):
        np.save(p / "bp.npy", np.linspace(0.0, 1.0, 5))
        raw = (p / "bp.npy").read_bytes().replace(b"(5,)", b"(1000000001,)".ljust(4)[:4] if False else b"(5,)")
        header = raw.replace(b"'shape': (5,)", b"'shape': (1000000001,)")
        (p / "bp.npy").write_bytes(header)
        _mult(d)["breakpoints"] = "bp.npy"
    _spoil(tmp_path / "n", capsys, npy, r"bp\.npy: the header declares shape \(1000000001,\).* cut short or forged")

    def cut_yaml(d, p):
        (p / "m.yaml").write_text("basis: lagrange\ndegree: 1\nends: drop\nbreakpoints: [0, 0.25, 0.5,")
        d["levels"][0]["multipliers"] = "m.yaml"
    _spoil(tmp_path / "y", capsys, cut_yaml, r"m\.yaml: not readable YAML")

    def cut_list(d, p):
        (p / "m.yaml").write_text("basis: lagrange\ndegree: 1\nends: drop\nbreakpoints:\n- 0\n- 0.25\n- 0.5\n")
        d["levels"][0]["multipliers"] = "m.yaml"
    _spoil(tmp_path / "l", capsys, cut_list, r"m\.yaml: multipliers\.breakpoints: runs from 0\.0 to 0\.5")


def test_description_files_are_read(tmp_path):
    """The same description from a .yaml file with .txt / .npy arrays gives the inline one's β."""
    import yaml

    data, path = _base(tmp_path)
    ref = system_rows(load_manifest(path, 1), notes=io.StringIO())[0]["beta"]
    mult = _mult(data)
    (tmp_path / "bp.txt").write_text("\n".join(map(repr, mult["breakpoints"])) + "\n")
    np.save(tmp_path / "rows.npy", np.arange(3))
    (tmp_path / "m.yaml").write_text(yaml.safe_dump(dict(mult, breakpoints="bp.txt", rows="rows.npy")))
    data["levels"][0]["multipliers"] = "m.yaml"
    path.write_text(yaml.safe_dump(data))
    assert system_rows(load_manifest(path, 1), notes=io.StringIO())[0]["beta"] == ref


def test_a_description_too_large_for_the_memory_is_refused_before_its_gram(tmp_path, capsys, monkeypatch):
    """10⁵ intervals from an 800 kB .npy and a B of 10⁵ rows with 10 entries: the H Gram would need
    ~1 TB (8 m² · 10 and the log kernel's pairs); the memory gate refuses it in the dry run."""
    import scipy.io
    import yaml

    from infsup_contact.systems import multiplier_gram

    n = 100_000
    np.save(tmp_path / "bp.npy", np.linspace(0.0, 1.0, n + 1))
    B = sp.coo_matrix((np.ones(10), (np.arange(10), np.arange(10))), shape=(n - 1, 10))
    scipy.io.mmwrite(tmp_path / "B.mtx", B)
    scipy.io.mmwrite(tmp_path / "A.mtx", sp.identity(10, format="coo"))
    (tmp_path / "levels.yaml").write_text(yaml.safe_dump({
        "norm": "H", "gamma": {"shape": "segment", "length": 1.0},
        "levels": [{"h": 1e-5, "A": "A.mtx", "B": "B.mtx",
                    "multipliers": {"basis": "lagrange", "degree": 1, "ends": "drop", "breakpoints": "bp.npy"},
                    "traces": [{"basis": "lagrange", "degree": 1, "breakpoints": [0.0, 1.0], "columns": [0, 1]}]}]}))
    called = []
    monkeypatch.setattr(multiplier_gram, "gram", lambda *a: called.append(a))
    assert main(["beta", "--system", str(tmp_path / "levels.yaml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "invalid --system" in err and "memory" in err and "TiB peak" in err, err
    assert not called


@pytest.mark.parametrize("value,match", [
    ({"x": {"basis": "lagrange", "degree": 1, "breakpoints": [0, 2]}}, r"m\.yaml: levels\[0\]\.multipliers: missing key 'y'"),
    ({"x": {"basis": "lagrange", "degree": 1, "breakpoints": [0, 1], "rows": [0, 1]},
      "y": {"basis": "lagrange", "degree": 1, "breakpoints": [0, 1]}}, r"multipliers\.x\.rows: give the face's row order once"),
    ({"x": [0, 1], "y": {}}, r"multipliers\.x: expected a segment form"),
    ({"x": {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 2]},
      "y": {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 0.5, 1]}, "rows": [1, 0, 0]},
     r"multipliers\.rows: expected a permutation of 0\.\.1"),
    ({"x": {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 2]},
      "y": {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 0.5, 2]}}, r"multipliers\.y\.breakpoints: runs from 0\.0 to 2\.0; it must cover Γ = \[0, 1\.0\]"),
])
def test_hostile_face_descriptions(value, match):
    with pytest.raises(SystemFileError, match=match):
        describe("m.yaml", 0, value, Gamma("rectangle", (2.0, 1.0)))


def test_face_rows_permute_the_gram():
    """rows: on a face permutes G exactly (P_0 ⊗ P_0 on 2 × 3 cells: the default i + n_x j)."""
    x = {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 1, 2]}
    y = {"basis": "discontinuous", "degree": 0, "breakpoints": [0, 0.25, 0.5, 1]}
    plain = describe("m.yaml", 0, {"x": x, "y": y}, Gamma("rectangle", (2.0, 1.0)))
    rows = [5, 3, 1, 0, 2, 4]
    perm = describe("m.yaml", 0, {"x": x, "y": y, "rows": rows}, Gamma("rectangle", (2.0, 1.0)))
    G, Gp = gram(plain, "L2")[0], gram(perm, "L2")[0]
    assert np.array_equal(Gp[np.ix_(rows, rows)], G)
    np.testing.assert_allclose(np.diag(G), [0.25, 0.25, 0.25, 0.25, 0.5, 0.5], rtol=1e-15)  # |cell| in order i + 2 j


# ---------------------------------------------------------------- the distance to the exact mortar coupling
@pytest.mark.parametrize("k", [1, 2])
def test_slave_side_quadrature_is_exact_only_on_matching_meshes(tmp_path, k):
    """B_1 integrated by the Gauss rule of the multiplier mesh (= Ω2's trace, the slave side) only,
    as codes without segmentation do: its distance to the exact coupling is round-off on matching
    meshes and the integration error on non-matching ones, equal to ‖B_slave − B‖ / ‖B‖ with the
    suite's B (the exact coupling of :mod:`~infsup_contact.discretization.gamma.coupling`: a second route)."""
    from infsup_contact.discretization.gamma.coupling import weighted_values
    from infsup_contact.systems.export import _suite_parts

    out = {}
    for offset in (0, 1):
        levels, norm, gamma = suite_levels("T3", k, NS, offset)
        slave = []
        for n, (h, A, B, G, mult, traces) in zip(NS, levels):
            _, _, space, segment, sides = _suite_parts("T3", k, n + offset, n, "structured", "omega2", None)
            x, w = segment.quadrature(space.breakpoints, k + space.degree)
            B1 = np.asarray(weighted_values(space, x, w).T @ segment.trace_basis(sides[0].trace, x))
            Bs = B.toarray()
            Bs[:, sides[0].ndof - B1.shape[1]:sides[0].ndof] = -B1
            slave.append((h, A, sp.csr_matrix(Bs), G, mult, traces))
            out[offset, n] = np.linalg.norm(Bs - B.toarray()) / np.linalg.norm(B.toarray())
        m = load_manifest(write_system(tmp_path / f"{offset}", slave, "npz", "slave", norm, gamma=gamma), 1)
        for n, row in zip(NS, system_rows(m, notes=io.StringIO())):
            assert abs(row["coupling_distance"] - out[offset, n]) <= 1e-12
            assert (row["coupling_distance"] <= 1e-14) == (offset == 0)
    assert min(out[1, n] for n in NS) > 1e-3  # N1 = N2 + 1: visibly inexact


def test_the_distance_sees_a_wrong_sign_and_is_absent_without_traces(tmp_path):
    levels, norm, gamma = suite_levels("DUAL", 1, NS, 1)
    flipped = [(h, A, -B, G, mult, [dict(t, sign=-t["sign"]) for t in traces]) for h, A, B, G, mult, traces in levels]
    m = load_manifest(write_system(tmp_path / "f", flipped, "mtx", "f", norm, gamma=gamma), 1)
    assert all(r["coupling_distance"] <= 1e-14 for r in system_rows(m, notes=io.StringIO()))
    wrong = [(h, A, B, G, mult, [dict(traces[0], sign=1), traces[1]]) for h, A, B, G, mult, traces in levels]
    m = load_manifest(write_system(tmp_path / "w", wrong, "mtx", "w", norm, gamma=gamma), 1)
    for row in system_rows(m, notes=io.StringIO()):  # body 1's block counted twice over: ‖2 B_1‖ / ‖B‖
        assert row["coupling_distance"] > 0.5
    none = [lv[:5] for lv in levels]
    m = load_manifest(write_system(tmp_path / "n", none, "mtx", "n", norm, gamma=gamma), 1)
    assert all(np.isnan(r["coupling_distance"]) for r in system_rows(m, notes=io.StringIO()))


def _trace(change):
    def spoil(data, tmp_path):
        import yaml

        levels, *_ = suite_levels("T3", 1, (4,), 0)
        traces = levels[0][5]
        change(traces)
        data["levels"][0]["traces"] = yaml.safe_load(yaml.safe_dump(traces))
    return spoil


@pytest.mark.parametrize("change,match", [
    (lambda t: t[0].pop("columns"), r"levels\[0\]\.traces\[0\]: missing key 'columns'"),
    (lambda t: t[0].update(columns=t[0]["columns"][:-1]), r"traces\[0\]\.columns: expected 3 integers in -1\.\.\d+"),
    (lambda t: t[0].update(columns=[10 ** 6] * 3), r"traces\[0\]\.columns: expected 3 integers"),
    (lambda t: t[0].update(columns=[5, 5, 6]), r"traces\[0\]\.columns: a column of B named twice"),
    (lambda t: t[1].update(sign=2), r"traces\[1\]\.sign: expected -1 or 1"),
    (lambda t: t[1].update(rows=[0]), r"traces\[1\]\.rows: a trace gives its columns"),
    (lambda t: t[1].update(degree=9), r"traces\[1\]\.degree: expected an integer in 0\.\.7"),
    (lambda t: t.extend([t[0]]), r"levels\[0\]\.traces: expected a list of one or two"),
])
def test_hostile_traces(tmp_path, capsys, change, match):
    _spoil(tmp_path, capsys, _trace(change), match, dry=False)


def test_a_face_of_ten_billion_functions_is_refused_before_its_numbering(tmp_path):
    """Two 10⁵-interval axes (800 kB .npy each) describe 10¹⁰ functions: refused before an array
    of that length is made (the Gram's gate comes later, after B's rows)."""
    np.save(tmp_path / "x.npy", np.linspace(0.0, 1.0, 100_001))
    form = {"basis": "discontinuous", "degree": 0, "breakpoints": "x.npy"}
    with pytest.raises(SystemFileError, match=r"multipliers: describes 10000000000 functions: their numbering alone"):
        describe(tmp_path / "levels.yaml", 0, {"x": form, "y": form}, Gamma("rectangle", (1.0, 1.0)))


def test_a_general_form_is_not_reshaped_from_another_shape():
    """dofs of shape (2, 4) where (4, 2) is meant: refused, not silently reshaped (only a flat
    array from a file is read interval by interval)."""
    form = {"breakpoints": [0, 0.25, 0.5, 0.75, 1], "degree": 1, "dofs": [[0, 1, 1, 2], [2, 3, 3, 4]]}
    with pytest.raises(SystemFileError, match=r"dofs: expected an integer array of shape \(N, s \+ 1\) = \(4, 2\)"):
        describe("m.yaml", 0, form, Gamma("segment", (1.0,)))


def test_elastic_model_described(tmp_path):
    """The elastic model (plane strain, the normal component on Γ): the same agreement, traces exact."""
    from infsup_contact.models.elastic import ELASTIC

    m = _manifest(tmp_path, "T3", 2, 1, model=ELASTIC)
    for n, row in zip(NS, system_rows(m, notes=io.StringIO())):
        ref, = beta_rows("structured", 2, n + 1, n, ["T3"], norms=("H",), model=ELASTIC)
        _agree(row, ref)
        assert row["coupling_distance"] <= 1e-14


@pytest.mark.parametrize("norm", ["L2", "h-L2", "given"])
def test_a_description_under_the_other_norms(tmp_path, norm):
    """The same export judged in another norm (the action's override): L2 and h-L2 take G, the L2
    mass, checked against the description (β the L2 one, h-L2 β/√h); given takes G as it is; the
    traces' distance in every norm."""
    import yaml

    levels, _, gamma = suite_levels("T3", 1, NS, 1)
    path = write_system(tmp_path, levels, "mtx", "t3", "H", gamma=gamma)
    described = system_rows(load_manifest(path, 1), notes=io.StringIO())
    data = yaml.safe_load(path.read_text())
    path.write_text(yaml.safe_dump(dict(data, norm=norm)))
    rows = system_rows(load_manifest(path, 1), notes=io.StringIO())
    for n, row, ref in zip(NS, rows, described):
        weight = 1.0 / np.sqrt(row["h"]) if norm == "h-L2" else 1.0
        assert abs(row["beta"] - ref["beta_L2"] * weight) <= 1e-12 * row["beta"]
        assert row["coupling_distance"] <= 1e-14 and "beta_L2" not in row


@pytest.mark.parametrize("k", [1, 2])
def test_constrained_end_multipliers_described_in_full(tmp_path, capsys, k):
    """The FE way to make μ vanish at Γ's ends: R5.2 (continuous P_k, ends kept) described in full,
    its end rows constrained in the export (B's rows zero, G's rows unit). The Gram of the
    constrained space is the description's without those rows: T3's β_h to 1e-10, the L2 check on
    the rows kept, the traces exact there, and a note."""
    levels, norm, gamma = suite_levels("R5.2", k, NS, 1)
    spoiled = []
    for h, A, B, G, mult, traces in levels:
        B, G = B.tolil(), G.copy()
        for r in (0, B.shape[0] - 1):  # the end nodes: rows 0 and m - 1 (left to right)
            B[r, :] = 0.0
            G[r, :] = G[:, r] = 0.0
            G[r, r] = 1.0
        spoiled.append((h, A, B.tocsr(), G, mult, traces))
    m = load_manifest(write_system(tmp_path, spoiled, "mtx", "r52-ends", norm, gamma=gamma), 1)
    notes = io.StringIO()
    for n, row in zip(NS, system_rows(m, notes=notes)):
        ref, = beta_rows("structured", k, n + 1, n, ["T3"], norms=("H",))
        assert row["kernel_dim"] == 0 and row["removed_multipliers"] == 2
        assert abs(row["beta"] - ref["beta"]) <= 1e-10 * ref["beta"]
        assert row["coupling_distance"] <= 1e-14
    assert "2 constrained multipliers" in notes.getvalue()


def test_a_body_without_free_dofs_on_gamma_has_no_trace(tmp_path):
    """N1 = 1 at k = 1: Ω1's trace has no free dof (Γ's ends are fixed), so only Ω2's trace is
    described (sign +1 as written), and the distance stays round-off."""
    levels, norm, gamma = suite_levels("R5.2", 1, (2, 4), -1)
    assert [len(lv[5]) for lv in levels] == [1, 2] and levels[0][5][0]["sign"] == 1
    m = load_manifest(write_system(tmp_path, levels, "mtx", "n1", norm, gamma=gamma), 1)
    assert all(r["coupling_distance"] <= 1e-14 for r in system_rows(m, notes=io.StringIO()))
