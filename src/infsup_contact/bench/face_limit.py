"""The face's limit: the cheapest known computation of the same β_h rows, and its flop count.

``limit`` (``bench --what face``) is timed on given inputs (the assembled stiffness, the interface
operators S and the Gram matrices G of every (case, norm)) and does only what no route of the same
rows can skip:

* the factorization at its flop floor: a plain sparse Cholesky (PARDISO, METIS order; no Schur
  complement) of each body's reflection parity parts, where the body has the square's reflections
  (:func:`parity_parts`; else of the whole body), and of one body only on a pair that is the mirror
  image of it (matching meshes: the other body's factors are the first's, permuted);
* the pencils in parity blocks: one dense generalized ``eigh`` (eigenvalues only) of each block
  Q_cᵀ S Q_c, Q_cᵀ G Q_c of the reflections' split of the space
  (:func:`~infsup_contact.solvers.symmetry.split_of`; the whole pencil where it has none).

Its flops (``limit_gflop``): PARDISO's own count of each Cholesky (``iparm[18]``, MFLOP of the
numerical factorization) + 8/3 m³ per block of size m (Cholesky of G m³/3, reduction to standard
form m³, tridiagonalization 4/3 m³; the eigenvalues of a tridiagonal matrix are O(m²)). Every row
reports ``gflop_per_s`` = limit_gflop / its seconds: the limit's own flop rate, and for ``ours`` the
rate at which it does the floor's work.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..la import pardiso
from ..solvers.symmetry import split_of

from ..la.body_parity import parity_parts as _parity_parts
from ..models.body_symmetry import mirror_permutation as _mirror
from ..models.body_symmetry import parity_bases as _parity_bases

EIGH_FLOPS_PER_M3 = 8.0 / 3.0
"""Flops of a dense generalized ``eigh`` of size m, eigenvalues only, per m³ (module text)."""


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


def pencil_gflop(blocks: dict) -> float:
    """The pencils' flops (GFLOP): :data:`EIGH_FLOPS_PER_M3` m³ per block."""
    return sum(EIGH_FLOPS_PER_M3 * float(S.shape[0]) ** 3 for pairs in blocks.values() for S, _ in pairs) / 1e9


def face_limit(setup, ops: dict):
    """(the limit as a callable returning {(case, norm): ascending β² values}, a callable giving
    its GFLOP after a run): the floor's Choleskys + the pencils' blocks (module text)."""
    mats = floor_matrices(setup.sides)
    blocks = pencil_blocks(setup, ops)
    counted = {"factor": float("nan")}

    def run():
        counted["factor"] = sum(cholesky(K) for K in mats)
        return {key: np.sort(np.concatenate([sla.eigh(S, G, eigvals_only=True, check_finite=False)
                                             for S, G in pairs])) for key, pairs in blocks.items()}

    return run, lambda: counted["factor"] + pencil_gflop(blocks)
