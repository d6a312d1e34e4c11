"""Descriptions that cannot be checked, and what a contact verdict advises (a real-client rerun).

A ``norm: H`` description turns B into β_h through a Gram the tool assembles itself: a wrong one
gives a wrong β_h with exit 0. Four hostile descriptions of the suite's own exports — two rows of
B swapped, the breakpoints of a graded mesh for a B assembled on a uniform one, ``basis: dual`` for
Lagrange rows, DOLFINx's P_3 (GLL nodes) described with equispaced nodes — must be refused
(no G, no traces), refused by the L² mass (G), or INCONCLUSIVE (traces only, no body's block
exact); the right description gets the suite's own verdict. The truth is always the suite's route
(the exported system described correctly), never a number written here.
"""
from __future__ import annotations

import io

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.cli import main
from infsup_contact.systems.export import suite_levels, write_system
from infsup_contact.systems.levels import system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest
from infsup_contact.systems.multiplier_basis import Gamma, describe, gll_nodes
from infsup_contact.systems.readers import SystemFileError

CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
NS = (8, 16, 32)  # T3, k = 1 is STABLE here (on 4, 8, 16 its slope interval is still too wide)
SEGMENT = Gamma("segment", (1.0,))


def _swapped(h, A, B, G, mult, traces):
    p = np.arange(B.shape[0])
    p[[1, 2]] = p[[2, 1]]
    return h, A, B[p], G[np.ix_(p, p)], mult, traces


def _graded(h, A, B, G, mult, traces):
    return h, A, B, G, dict(mult, breakpoints=(np.asarray(mult["breakpoints"]) ** 1.5).tolist()), traces


def _dual(h, A, B, G, mult, traces):
    return h, A, B, G, dict(mult, basis="dual"), traces


def _to_gll(h, A, B, G, mult, traces):
    """The same P_k space with its basis on GLL nodes (DOLFINx's P_3): B and G transformed by
    ψ^gll_i = Σ_j ψ^gll_i(x_j) ψ^eq_j (x_j the equispaced nodes), the description unchanged."""
    eq = describe("m.yaml", 0, mult, SEGMENT).space
    T = gll_nodes(eq).evaluate(eq.nodes()).T
    return h, A, sp.csr_matrix(T @ B.toarray()), T @ G @ T.T, mult, traces


HOSTILE = {"swapped rows": ("T3", 1, _swapped), "graded breakpoints": ("T3", 1, _graded),
           "dual for Lagrange": ("T3", 1, _dual), "GLL P3 as equispaced": ("T3", 3, _to_gll)}


def _levels(case, k, ns=NS):
    levels, norm, gamma = suite_levels(case, k, ns, 0)
    return levels, norm, gamma


def _write(tmp_path, name, levels, norm, gamma, g=True, traces=True):
    kept = [(h, A, B, G if g else None, mult) + ((tr,) if traces else ()) for h, A, B, G, mult, tr in levels]
    return load_manifest(write_system(tmp_path / name, kept, "npz", name, norm, gamma=gamma), min_levels=1)


@pytest.mark.parametrize("hostile", sorted(HOSTILE))
def test_a_description_with_neither_g_nor_traces_is_refused(tmp_path, capsys, hostile):
    case, k, spoil = HOSTILE[hostile]
    levels, norm, gamma = _levels(case, k, NS[:1])
    m = _write(tmp_path, "bare", [spoil(*lv) for lv in levels], norm, gamma, g=False, traces=False)
    with pytest.raises(SystemFileError, match=r"levels\[0\]: norm: H with the multipliers described needs G .* or "
                                              r"traces .*to check the description"):
        system_rows(m, notes=io.StringIO())
    assert main(["verdict", "--system", str(m.path), "--dry-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err


@pytest.mark.parametrize("hostile", sorted(HOSTILE))
def test_a_wrong_description_with_g_is_refused_by_the_mass(tmp_path, hostile):
    case, k, spoil = HOSTILE[hostile]
    levels, norm, gamma = _levels(case, k, NS[:1])
    m = _write(tmp_path, "g", [spoil(*lv) for lv in levels], norm, gamma, traces=False)
    with pytest.raises(SystemFileError, match=r"G0.npz: differs from the L2 mass of levels\[0\].multipliers"):
        system_rows(m, notes=io.StringIO())


@pytest.mark.parametrize("hostile", sorted(HOSTILE))
def test_a_wrong_description_with_traces_only_is_inconclusive(tmp_path, hostile):
    """Without G the traces check the description only where one body's block is exact: a wrong
    description spoils every block, so the verdict is INCONCLUSIVE, naming the key, where the
    right description with the same traces gets the verdict of the full export (STABLE)."""
    case, k, spoil = HOSTILE[hostile]
    levels, norm, gamma = _levels(case, k, NS if k == 1 else (4, 8, 16))
    truth, _ = system_verdict(_write(tmp_path, "truth", levels, norm, gamma), **CRITERION, notes=io.StringIO())
    right, rows = system_verdict(_write(tmp_path, "right", levels, norm, gamma, g=False), **CRITERION,
                                 notes=io.StringIO())
    assert truth["verdict"] == right["verdict"] == "STABLE", truth["evidence"]
    assert all(r["description_check"] == "coupling" for r in rows)
    err = io.StringIO()
    out, rows = system_verdict(_write(tmp_path, "wrong", [spoil(*lv) for lv in levels], norm, gamma, g=False),
                               **CRITERION, notes=err)
    assert out["verdict"] == "INCONCLUSIVE" and "levels[0, 1, 2].multipliers unchecked" in out["evidence"]
    assert all(r["description_check"] == "none" for r in rows)
    assert err.getvalue().count("multipliers unchecked") == 3


def test_gll_nodes_describe_dolfinx_p3_exactly(tmp_path):
    """DOLFINx's P_3 (basix's default variant, GLL nodes on an interval) with ``nodes: gll``: the
    mass check passes, B is the exact coupling, and β_h per level is the suite's own (β is
    basis-independent: B → T B, G → T G Tᵀ is a congruence of the pencil)."""
    levels, norm, gamma = _levels("T3", 3, (4, 8, 16))
    gll = [_to_gll(*lv)[:4] + (dict(lv[4], nodes="gll"), lv[5]) for lv in levels]
    ref = system_rows(_write(tmp_path, "ref", levels, norm, gamma), notes=io.StringIO())
    out, rows = system_verdict(_write(tmp_path, "gll", gll, norm, gamma), **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "STABLE"
    for r, s in zip(rows, ref):
        assert abs(r["beta"] - s["beta"]) <= 1e-8 * s["beta"] and r["coupling_distance"] <= 1e-13
        assert abs(r["beta_L2"] - s["beta_L2"]) <= 1e-8 * s["beta_L2"]


@pytest.mark.parametrize("s", [1, 2, 3, 4, 5])
def test_gll_nodes_are_the_gauss_lobatto_points(s):
    """The GLL basis is nodal at the ends and at the roots of P_s' (for s = 3: (1 ∓ 1/√5)/2), and
    up to s = 2 it is the equispaced basis itself."""
    from numpy.polynomial import legendre

    eq = describe("m.yaml", 0, {"basis": "lagrange", "degree": s, "breakpoints": [0.0, 0.5, 1.0]}, SEGMENT).space
    gll = gll_nodes(eq)
    t = np.concatenate([[0.0], (np.sort(legendre.Legendre.basis(s).deriv().roots()) + 1) / 2, [1.0]])
    if s == 3:
        np.testing.assert_allclose(t[1:3], [(1 - 5 ** -0.5) / 2, (1 + 5 ** -0.5) / 2], rtol=1e-15)
    x = np.concatenate([0.5 * t[:-1], 0.5 + 0.5 * t])  # both intervals' nodes, the middle vertex once
    np.testing.assert_allclose(gll.evaluate(x), np.eye(gll.dim), atol=1e-13)
    assert (gll is eq) == (s <= 2)


@pytest.mark.parametrize("form,match", [
    ({"basis": "lagrange", "degree": 3, "nodes": "gauss"}, r"multipliers\.nodes: 'gauss': expected equispaced or gll"),
    ({"basis": "dual", "degree": 1, "nodes": "gll"}, r"multipliers\.nodes: 'gll': expected equispaced \(nodes: only "
                                                     r"with basis lagrange or discontinuous\)"),
])
def test_hostile_nodes(form, match):
    with pytest.raises(SystemFileError, match=match):
        describe("m.yaml", 0, dict(form, breakpoints=[0.0, 0.5, 1.0]), SEGMENT)


def test_slave_side_quadrature_without_g_is_checked_by_its_exact_block(tmp_path):
    """B_1 integrated on the multiplier mesh only (N1 = N2 + 1: the coupling of body 1 inexact,
    body 2's exact): the description is still checked, by body 2's block, and the verdict is that
    of the same levels with G."""
    from infsup_contact.discretization.gamma.coupling import weighted_values
    from infsup_contact.systems.export import _suite_parts

    levels, norm, gamma = suite_levels("T3", 1, NS, 1)
    slave = []
    for n, (h, A, B, G, mult, traces) in zip(NS, levels):
        _, _, space, segment, sides = _suite_parts("T3", 1, n + 1, n, "structured", "omega2", None)
        x, w = segment.quadrature(space.breakpoints, 1 + space.degree)
        B1 = np.asarray(weighted_values(space, x, w).T @ segment.trace_basis(sides[0].trace, x))
        Bs = B.toarray()
        Bs[:, sides[0].ndof - B1.shape[1]:sides[0].ndof] = -B1
        slave.append((h, A, sp.csr_matrix(Bs), G, mult, traces))
    with_g, _ = system_verdict(_write(tmp_path, "g", slave, norm, gamma), **CRITERION, notes=io.StringIO())
    out, rows = system_verdict(_write(tmp_path, "t", slave, norm, gamma, g=False), **CRITERION, notes=io.StringIO())
    assert all(r["description_check"] == "coupling" and r["coupling_distance"] > 1e-3 for r in rows)
    assert out["verdict"] == with_g["verdict"] and "unchecked" not in out["evidence"]


# ---------------------------------------------------------------- what an undeclared kernel's verdict advises
def test_a_contact_kernel_is_called_the_instability(tmp_path):
    """R5.2 (its two end multipliers: a kernel of Bᵀ) exported by the suite, with its description
    (gamma) and as a bare norm: L2 system (the interface told from B): the advice says the kernel
    is the instability and how to remove it, not to declare it like a constant pressure."""
    for norm in ("H", "L2"):
        levels, mnorm, gamma = suite_levels("R5.2", 1, (4, 8, 16), 0)
        if norm == "L2":
            levels, mnorm, gamma = [lv[:4] for lv in levels], "L2", None
        path = write_system(tmp_path / norm, levels, "npz", "R5.2", mnorm, gamma=gamma)
        out, _ = system_verdict(load_manifest(path), **CRITERION, notes=io.StringIO())
        assert out["verdict"] == "UNSTABLE" and out["kernel_dim"] == 2
        assert "kernel of B^T is the instability" in out["evidence"] and "drop the multipliers" in out["evidence"]
        assert "constant pressure" not in out["evidence"]


def test_a_whole_body_kernel_may_be_declared(tmp_path):
    """A B over every dof (a Stokes divergence) with a repeated row: a kernel that may be a known
    one, so the advice is to declare it (a constant pressure), not the contact advice."""
    levels, _, _ = suite_levels("T3", 1, (4,), 0)
    h, A, B, G = levels[0][:4]
    rng = np.random.default_rng(3)
    Bw = rng.standard_normal((5, A.shape[0]))
    Bw[4] = Bw[3]
    path = write_system(tmp_path, [(1.0 / n, A, sp.csr_matrix(Bw), np.eye(5)) for n in (1, 2, 4)], "npz", "whole")
    out, _ = system_verdict(load_manifest(path), **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "UNSTABLE" and "constant pressure" in out["evidence"]
    assert "instability" not in out["evidence"]


def test_a_permutation_the_mass_cannot_see_is_refused_by_the_traces(tmp_path):
    """P_0 on equal cells (R5.4, k = 1): M = h I, so rows 1 and 3 swapped pass the mass check;
    with traces, every body's block has a row √2-ish from its exact coupling (quadrature: ≤ 0.29):
    refused, naming the key. The unswapped export passes (its distance is round-off)."""
    levels, norm, gamma = _levels("R5.4", 1, (8,))
    h, A, B, G, mult, traces = levels[0]
    p = np.arange(B.shape[0])
    p[[1, 3]] = p[[3, 1]]
    assert np.array_equal(G[np.ix_(p, p)], G)
    m = _write(tmp_path, "swapped", [(h, A, B[p], G, mult, traces)], norm, gamma)
    with pytest.raises(SystemFileError, match=r"levels\[0\]\.multipliers: a row of B is 1\.\d+ .*on every body.*"
                                              r"cannot see a permutation of equal masses"):
        system_rows(m, notes=io.StringIO())
    row, = system_rows(_write(tmp_path, "right", levels, norm, gamma), notes=io.StringIO())
    assert row["description_check"] == "mass" and row["coupling_distance"] <= 1e-14


def test_a_factor_on_b_is_not_a_wrong_row_order(tmp_path):
    """B·(1/h) (a mortar code's E/h) with G and traces: not refused as a permutation (the row check
    compares with the best multiple of the exact coupling); β_h carries the factor, as without traces."""
    levels, norm, gamma = _levels("T3", 1, (8,))
    h, A, B, G, mult, traces = levels[0]
    row, = system_rows(_write(tmp_path, "scaled", [(h, A, B / h, G, mult, traces)], norm, gamma), notes=io.StringIO())
    ref, = system_rows(_write(tmp_path, "ref", levels, norm, gamma), notes=io.StringIO())
    assert abs(row["beta"] - ref["beta"] / h) <= 1e-10 * row["beta"] and row["description_check"] == "mass"
