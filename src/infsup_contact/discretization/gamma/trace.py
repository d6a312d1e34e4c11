"""A side's trace on Γ: its Γ dofs, trace elements, partition, and the caches of its basis values.

:class:`GammaTrace` is what a model's side operator hands the engine about Γ (``side.trace``);
it carries its interface (``trace.gamma``, :mod:`.gamma.interface`), which evaluates the basis.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

BASIS_CACHE_SIZE = 4
"""Point sets whose trace basis values a trace keeps (:meth:`GammaTrace.cached_basis`)."""
_BASIS_LOCK = threading.RLock()
"""Held while a trace's basis values are looked up or computed: multiplier spaces run side by side
(:mod:`infsup_contact.solvers.side_by_side`) ask for the same point sets, which are computed once,
and NGSolve's shape functions are evaluated by one thread at a time."""


@dataclass(frozen=True)
class GammaTrace:
    """The Γ trace of a displacement space V_{h,i} = H1(mesh_i, order=k, dirichlet="dir").

    Attributes
    ----------
    fes : ngsolve.H1
        The displacement space.
    gamma_dofs : ndarray of int
        Free NGSolve dofs that live on Γ (endpoint vertices are Dirichlet), sorted.
    elements : list
        Γ boundary elements, as the interface keeps them: (x_first, x_second, dofs, element)
        on the segment, (vertex coordinates (nv, 2), dofs, element) on the face.
    breakpoints : ndarray
        The trace partition (for a :class:`Segment`: sorted x of its vertices); consumers
        read it as :attr:`partition`.
    gamma : Interface
        The interface this trace lives on.
    basis_cache : dict
        Values of the Γ-dof basis at point sets already asked for (:meth:`Interface.trace_basis`).
    sparse_cache : dict
        The same values as CSR matrices (:meth:`cached_sparse_basis`), kept and dropped with
        ``basis_cache`` (:meth:`forget_basis`).
    """

    fes: object
    gamma_dofs: np.ndarray
    elements: list
    breakpoints: np.ndarray
    gamma: "Interface" = field(default=None, repr=False, compare=False)
    basis_cache: dict = field(default_factory=dict, repr=False, compare=False)
    sparse_cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def partition(self):
        """The trace partition of this side on Γ (opaque: hand it back to :attr:`gamma`)."""
        return self.breakpoints

    def cached_basis(self, x: np.ndarray, compute) -> np.ndarray:
        """``compute(x)``, the dense Γ-dof basis values at the points ``x``, kept read-only on the
        trace for the next request of the same points (at most :data:`BASIS_CACHE_SIZE` point
        sets): every multiplier space of one degree on one G_h asks for the same quadrature points,
        and NGSolve evaluates one point at a time (:meth:`Interface.trace_basis`)."""
        key = _points_key(x)
        with _BASIS_LOCK:
            phi = self.basis_cache.get(key)
            if phi is None:
                phi = compute(x)
                phi.flags.writeable = False
                if len(self.basis_cache) >= BASIS_CACHE_SIZE:
                    self.forget_basis()
                self.basis_cache[key] = phi
        return phi

    def cached_sparse_basis(self, x: np.ndarray):
        """:meth:`Interface.trace_basis` at ``x`` as CSR, made once per point set for a sweep of
        multiplier spaces (:func:`~.gamma.coupling.coupling_matrix`); its row slices are, bit for bit,
        ``csr_matrix`` of the dense slices (sorted indices, no stored zeros). An interface with a
        ``sparse_trace_basis`` (the face) makes it without the dense values."""
        key = _points_key(x)
        with _BASIS_LOCK:
            phi = self.sparse_cache.get(key)
            if phi is None:
                phi = self.gamma.sparse_trace_basis(self, x)
                if phi is None:
                    phi = sp.csr_matrix(self.gamma.trace_basis(self, x))
                if len(self.sparse_cache) >= BASIS_CACHE_SIZE:
                    self.sparse_cache.clear()
                self.sparse_cache[key] = phi
        return phi

    def forget_basis(self) -> None:
        """Drop the kept basis values, dense and sparse (a benchmark's fresh state)."""
        with _BASIS_LOCK:
            self.basis_cache.clear()
            self.sparse_cache.clear()


def _points_key(x: np.ndarray) -> bytes:
    """The cache key of a point set: its coordinates' bytes as float64, C order."""
    return np.ascontiguousarray(x, dtype=float).tobytes()
