"""The face's limit: the cheapest known computation of the same β_h rows, and its flop count.

``limit`` (``bench --what face``) is timed on given inputs (the assembled stiffness, the interface
operators S and the Gram matrices G of every (case, norm)) and does only what no route of the same
rows can skip, on every core the request has:

* the factorization at its flop floor: a plain sparse Cholesky (PARDISO, METIS order; no Schur
  complement) of each body's reflection parity parts, where the body has the square's reflections
  (:func:`parity_parts`; else of the whole body), and of one body only on a pair that is the mirror
  image of it (matching meshes: the other body's factors are the first's, permuted); the parts side
  by side, one thread each, as ours factorizes them (k = 2, N = 24, two cores: 1.5-1.7 s, where
  one part after the other on PARDISO's two threads took 2.6-3.1 s);
* the pencils in parity blocks: the eigenvalues of each block Q_cᵀ S Q_c, Q_cᵀ G Q_c of the
  reflections' split of the space (:func:`~infsup_contact.solvers.symmetry.split_of`; the whole
  pencil where it has none), the blocks side by side (:func:`block_eigenvalues`, without the GIL).

Its flops (``limit_gflop``): PARDISO's own count of each Cholesky (``iparm[18]``, MFLOP of the
numerical factorization) + :data:`EIGH_FLOPS_PER_M3` m³ per block of size m. Every row reports
``gflop_per_s`` = limit_gflop / its seconds: the limit's own flop rate, and for ``ours`` the rate
at which it does the limit's work.
"""
from __future__ import annotations

import numpy as np

from ..la import openblas, pardiso
from ..la.threaded import concurrent_map
from ..solvers.symmetry import split_of

from ..la.body_parity import parity_parts as _parity_parts
from ..models.body_symmetry import mirror_permutation as _mirror
from ..models.body_symmetry import parity_bases as _parity_bases

EIGH_FLOPS_PER_M3 = 11.0 / 3.0
"""Flops of :func:`block_eigenvalues` of size m per m³: Cholesky of G m³/3, the standard form by two
triangular solves 2 m³, its tridiagonalization 4/3 m³ (the eigenvalues of a tridiagonal matrix are
O(m²)). LAPACK's dsygvd (``scipy.linalg.eigh``) does 8/3 m³, its standard form in m³ (sygst), but
scipy holds the GIL for the whole call, so its blocks run one after the other: at k = 2, N = 24 the
96 blocks took 2.0 s that way and 1.04-1.09 s side by side on two cores by this route."""


def parity_parts(side) -> list:
    """The sparse matrices the floor factorizes for one body: its parity parts K_c where the body
    has the square's reflections (a ``signature`` and the parity modules), else [K]."""
    K, n_gamma = side.stiffness, len(side.trace.gamma_dofs)
    signature = getattr(side, "signature", None)
    if signature is not None:
        bases = _parity_bases(signature, K, n_gamma)
        if bases is not None:
            return [part.stiffness for part in _parity_parts(K, n_gamma, bases).parts]
    return [K]


def floor_matrices(sides) -> list:
    """The matrices of both bodies' floor: side 2's none where it is side 1's mirror image."""
    out = parity_parts(sides[0])
    s1, s2 = sides
    mirrored = _mirror(getattr(s1, "signature", None), s1.stiffness, getattr(s2, "signature", None),
                       s2.stiffness, len(s1.trace.gamma_dofs)) is not None
    return out if mirrored else out + parity_parts(s2)


def cholesky(K) -> float:
    """One plain PARDISO Cholesky of K (released at once); its GFLOP by PARDISO's count
    (NaN where MKL does not load: then SuperLU factorizes, uncounted)."""
    if not pardiso.available():
        from .beta_bench import splu_best_order

        splu_best_order(K)
        return float("nan")
    handle = pardiso._Handle(K)
    handle.iparm[18] = -1  # report the numerical factorization's MFLOP (oneMKL: iparm[18] < 0)
    try:
        handle.call(12)
        return float(handle.iparm[18]) / 1e3
    finally:
        handle.release()


def pencil_blocks(setup, ops: dict) -> dict:
    """{(case, norm): [(S_c, G_c), ...]}: the pencils of the given operators in the blocks of their
    space's reflections (one block, the whole pencil, where the space has no split)."""
    out = {}
    for (case, norm), (S, G) in ops.items():
        split = split_of(setup.spaces[case], setup.gamma, setup.g_h, setup.k)
        if split is None:
            out[case, norm] = [(S, G)]
            continue
        out[case, norm] = [(s, g) for s, g in zip(split.blocks(S)[:-1], split.blocks(G)[:-1]) if s.shape[0]]
    return out


def block_eigenvalues(S: np.ndarray, G: np.ndarray) -> np.ndarray:
    """The eigenvalues of S x = λ G x (S symmetric, G positive definite), ascending: G = L Lᵀ, then
    those of L⁻¹ S L⁻ᵀ. Every step releases the GIL (potrf and trtrs by :mod:`~infsup_contact.la.openblas`,
    numpy's ``eigvalsh``), so blocks run side by side (:data:`EIGH_FLOPS_PER_M3`)."""
    L = openblas.cholesky_lower(G)
    X = openblas.solve_triangular(L, S, True)        # L⁻¹ S
    C = openblas.solve_triangular(L, X.T, True)      # L⁻¹ (L⁻¹ S)ᵀ = L⁻¹ S L⁻ᵀ
    return np.linalg.eigvalsh(C)


def pencil_gflop(blocks: dict) -> float:
    """The pencils' flops (GFLOP): :data:`EIGH_FLOPS_PER_M3` m³ per block."""
    return sum(EIGH_FLOPS_PER_M3 * float(S.shape[0]) ** 3 for pairs in blocks.values() for S, _ in pairs) / 1e9


def face_limit(setup, ops: dict):
    """(the limit as a callable returning {(case, norm): ascending β² values}, a callable giving
    its GFLOP after a run): the floor's Choleskys + the pencils' blocks, each side by side on the
    request's threads (module text)."""
    mats = floor_matrices(setup.sides)
    blocks = pencil_blocks(setup, ops)
    counted = {"factor": float("nan")}
    # the largest blocks first: the threads end together
    order = sorted(((key, i) for key, pairs in blocks.items() for i in range(len(pairs))),
                   key=lambda ki: -blocks[ki[0]][ki[1]][0].shape[0])

    def run():
        counted["factor"] = sum(concurrent_map(cholesky, mats))  # one thread each (one matrix: all)
        values = dict(zip(order, concurrent_map(lambda ki: block_eigenvalues(*blocks[ki[0]][ki[1]]), order)))
        return {key: np.sort(np.concatenate([values[key, i] for i in range(len(pairs))]))
                for key, pairs in blocks.items()}

    return run, lambda: counted["factor"] + pencil_gflop(blocks)
