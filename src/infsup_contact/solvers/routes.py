"""The route of one multiplier space through the pencil of (4.5): chosen once, named.

:func:`choose_route` decides, for a space and its couplings, how its pencils S m = β² G m are
solved and returns a :class:`Route`: ``"dense"`` (LAPACK, dim M up to
:data:`~infsup_contact.la.bottom.DENSE_MAX_M`), ``"bottom"`` (the kernel of Bᵀ deflated,
shift-invert Lanczos, :mod:`infsup_contact.la.bottom`) or ``"split"`` (the same on the
components of the reflections' split where the Gram matrices and the kernel split,
:mod:`infsup_contact.la.reflection`). The kernel of Bᵀ is decided here too
(:func:`space_kernel`): one decision serves every norm and every (c1, c2).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.gamma.coupling import coupling_matrices, trace_l2_norms
from ..la import bottom, face_parity, reflection
from . import spectra, symmetry
from .kernel import KernelDecision, bottom_kernel, coupling_kernel, scaled_couplings
from .spectra import gram_factor


ROUTES = ("dense", "bottom", "split")


def is_large(space) -> bool:
    """Whether ``space`` takes the large route (dim M > :data:`~infsup_contact.la.bottom.DENSE_MAX_M`):
    sparse couplings, no dense eigensolver."""
    return space.dim > bottom.DENSE_MAX_M


@dataclass(frozen=True)
class Route:
    """How the pencils of one multiplier space are solved (:func:`choose_route`).

    Attributes
    ----------
    name : str
        One of :data:`ROUTES`.
    kernel : KernelDecision
        The kernel of Bᵀ on the space (:func:`space_kernel`).
    factors : dict or spectra.SplitFactors
        {norm: Cholesky factor of G}; on ``"split"`` the factors of G's blocks (and of G on demand).
    split, parts
        The reflections' split and the kernel's bases per component (``"split"`` only).
    """

    name: str
    kernel: KernelDecision
    factors: object
    split: object = None
    parts: object = None

    @property
    def iterative(self) -> bool:
        return self.name != "dense"

    def spectra(self, S: np.ndarray, norms) -> tuple:
        """({norm: :class:`~.spectra.Spectrum`}, {norm: seconds}) of S m = β² G m. Dense: each
        norm's eigenproblem timed alone; otherwise the norms share work and each gets an equal share."""
        if not self.iterative and self.split is not None:  # the dense pencils in blocks
            te = time.perf_counter()
            out = spectra.dense_split_spectra(self.split, S, self.factors.split, self.kernel)
            if out is not None:
                return out, dict.fromkeys(norms, (time.perf_counter() - te) / len(norms))
            return Route(self.name, self.kernel, self.factors.whole).spectra(S, norms)
        if not self.iterative:
            out, seconds = {}, {}
            for norm in norms:
                te = time.perf_counter()
                out[norm] = spectra.spectrum(S, factor=self.factors[norm], kernel=self.kernel)
                seconds[norm] = time.perf_counter() - te
            return out, seconds
        te = time.perf_counter()
        out = spectra.large_spectra(S, self.factors, self.kernel, self.split, self.parts)
        return out, dict.fromkeys(norms, (time.perf_counter() - te) / len(norms))

    def betas_v1_zero(self, terms) -> dict:
        """β with v1 = 0 at c2 = 1 per norm (:func:`~.spectra.betas_v1_zero`)."""
        return spectra.betas_v1_zero(terms, self.factors, self.kernel, self.iterative, self.split)


def choose_route(space, couplings, sides, grams: dict, structural: int, g_h, k: int, trace_norms,
                 vectors: bool = False) -> Route:
    """The :class:`Route` of ``space`` on G_h = ``g_h``: its size decides dense or large; on the
    large route the reflections' split (:func:`.symmetry.split_of`) is taken where every Gram matrix
    and the kernel split (:func:`~infsup_contact.la.reflection.usable`). ``grams`` {norm: (G, info)},
    ``structural`` the proven kernel dimension, ``trace_norms`` the sides' :func:`~.coupling.trace_l2_norms`;
    ``vectors``: the kernel's basis on the dense route too (a worst mode, :mod:`.modes`)."""
    large = is_large(space)
    gamma = sides[0].trace.gamma
    split = symmetry.split_of(space, gamma, g_h, k, face_only=not large)
    kernel = space_kernel(couplings, sides, space, k, structural, grams["L2"][0] if "L2" in grams else None,
                          iterative=large, trace_norms=trace_norms, split=split, vectors=vectors)
    split, parts, halves = reflection.usable(split, grams, kernel if large else None)
    if split is not None:  # the dense route keeps its name: its pencils in blocks, whole spectra
        return Route("split" if large else "dense", kernel, spectra.SplitFactors(grams, halves), split, parts)
    return Route("bottom" if large else "dense", kernel, {norm: gram_factor(G) for norm, (G, _) in grams.items()})


def space_kernel(couplings, sides, space, k: int, structural: int, l2_gram=None,
                 iterative: bool = False, trace_norms=None, split=None, vectors: bool = False) -> KernelDecision:
    """The kernel of Bᵀ on ``space`` (:func:`~infsup_contact.solvers.kernel.coupling_kernel`):
    the couplings scaled by the L²(Γ) norms of the sides' trace basis functions and of the
    multiplier basis functions (the diagonal of the L² Gram matrix, computed if not given);
    ``structural`` = max(dim M − dim(W1 + W2), 0) is its proven part. One decision serves
    every norm and every (c1, c2): the kernel of B A⁻¹ Bᵀ depends on neither.

    ``iterative``: the bottom singular values only
    (:func:`~infsup_contact.solvers.kernel.bottom_kernel`, for dim M > :data:`~infsup_contact.la.bottom.DENSE_MAX_M`),
    W' from a rule :data:`LONGER_RULE_LARGE` longer, the couplings sparse (W sparse, the same
    entries); its ``vectors`` are returned in multiplier coordinates (a basis of the kernel of Bᵀ).
    ``trace_norms``: the sides' :func:`~.coupling.trace_l2_norms`, if already computed (they
    depend on the sides only, not on the space). ``split``: the reflections'
    (:func:`.symmetry.split_bottom_kernel` decides on the components where it holds). ``vectors``: the
    dense decision returns the kernel's basis too (the iterative one always does), in multiplier coordinates."""
    G = sides[0].trace.gamma.gram(space, "L2")[0] if l2_gram is None else l2_gram
    rows = [trace_l2_norms(s.trace, k) for s in sides] if trace_norms is None else trace_norms
    cols = np.sqrt(face_parity.diagonal(G))  # a Gram kept in parity blocks: without assembling it
    W = scaled_couplings(couplings, rows, cols)
    extra = LONGER_RULE_LARGE if iterative else LONGER_RULE
    longer = scaled_couplings(coupling_matrices([s.trace for s in sides], space, k, extra_degree=extra,
                                                sparse=iterative), rows, cols)
    if not iterative:
        error = np.linalg.norm(W - longer)
        decision = (symmetry.split_dense_kernel(W, split, structural, error, row_bases=_trace_components(sides))
                    if split is not None and not vectors else None)  # the components' SVDs where they decide
        decision = decision or coupling_kernel(W, structural, entry_error=error, vectors=vectors)
        return decision if decision.vectors is None else replace(decision, vectors=decision.vectors / cols[:, None])
    W, error = sp.csr_matrix(W), spla.norm(sp.csr_matrix(W - longer))
    decision = symmetry.split_bottom_kernel(W, split, structural, error) if split is not None else None
    if decision is None and split is not None:  # a certificate too close to round-off: the blocks'
        # dense SVDs (about (1/c)² of the whole one's flops and memory) before the whole W's
        decision = symmetry.split_dense_kernel(W, split, structural, error, vectors=True,
                                               row_bases=_trace_components(sides))
    decision = bottom_kernel(W, structural, entry_error=error) if decision is None else decision
    return replace(decision, vectors=decision.vectors / cols[:, None])  # W v = 0 ⇔ Bᵀ (v / cols) = 0


def _trace_components(sides) -> tuple | None:
    """The components of W's rows (the sides' trace dofs, side 1's first): blockdiag(P_1c, P_2c)
    of the sides' parity parts on Γ (``steklov_parts``), or None where a side has none or their
    counts differ (:func:`~.symmetry.split_dense_kernel` then keeps every row)."""
    parts = [getattr(side, "steklov_parts", None) for side in sides]
    if any(p is None for p in parts) or len({len(p) for p in parts}) != 1:
        return None
    return tuple(sp.block_diag([p[c][0] for p in parts], format="csr") for c in range(len(parts[0])))


LONGER_RULE = 6
"""Degree the entry-round-off rule W' of :func:`space_kernel` adds (three Gauss points more)."""
LONGER_RULE_LARGE = 2
"""The same above dim M = :data:`~infsup_contact.la.bottom.DENSE_MAX_M` (one point more, 16 instead of 36 points
per cell at k = s = 2: still exact, so W − W' is still round-off only; half the cost)."""
