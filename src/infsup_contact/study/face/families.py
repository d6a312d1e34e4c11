"""Kernels on the non-matching families of the face: the √2 pairs in 3D.

The 2D study's families (:mod:`~infsup_contact.discretization.gamma.mesh_series`) change the overlap pattern
of the two traces with N; ``sqrt2`` (round(√2 n)) makes the two grids share no interior line when
gcd(N1, N2) = 1 (5:7, 7:10), so the common coarsening of the traces is the single cell and
dim(W1 ∩ W2) = 0 on rectangles (:meth:`~infsup_contact.discretization.face.shapes.square.Square.trace_sum_dimension`).
On the face Ω2 is the finer side, N2 = round(√2 N1) (:mod:`infsup_contact.config.membranes3d`).

For every space, k and element on such a pair this compares three numbers
(:mod:`.claims.membranes3d`' reasoning):

* ``planar`` — the dimension argument max(dim M − dim(W1 + W2), 0) (:func:`~.claims.membranes3d.planar_kernel`),
  a lower bound of dim ker(B A⁻¹ Bᵀ) on any face;
* ``tensor`` — on rectangle faces, for the tensor-product spaces, 2 a1 a2 − min(a1, a2)² with the 1D
  counts a_i (:func:`~.claims.membranes3d.tensor_kernel_bound`), also a lower bound (None elsewhere);
* ``tensor_1d`` — on rectangle faces, for the tensor-product spaces, the kernel itself from the 1D
  factors alone (:func:`tensor_kernel_1d`): B_i = A_i ⊗ A_i, so dim ker = dim M − rank [A1 ⊗ A1; A2 ⊗ A2]
  with 1D integrals only — a route independent of the 3D meshes, solves and eigenproblem;
* ``kernel_dim`` — the numerical count (:func:`~infsup_contact.solvers.infsup.beta_rows_all`, L²
  Gram: the kernel of the pencil does not depend on the SPD Gram), with its decision
  (``clear`` or ``close``).

``prediction`` is :func:`~.claims.membranes3d.face_predictions`' verdict of "kernel = planar count" on this
pair alone (PASS, FAIL where the tensor bound exceeds the count, ``finding`` where only lower bounds
are known); ``as_predicted`` whether the numbers bear it out.

Run: ``python -m infsup_contact.study.face.families --N1 5 --k 1 2`` (CSV on stdout).
"""
from __future__ import annotations

import sys

import numpy as np

from ...discretization.spaces.registry import SPACES, ids_valid_for, space_ids
from ...discretization.gamma.mesh_series import FAMILY_RULES
from ...errors import InputError
from ...criteria.claims import FAIL, PASS
from ..claims.membranes3d import element_interfaces, face_predictions, is_tensor, planar_kernel, tensor_kernel_bound


def family_pair(family: str, n1: int) -> tuple:
    """(N1, N2 = rule(N1)): Ω2 the finer side (module docstring); InputError for an unknown family."""
    if family not in FAMILY_RULES:
        raise InputError("family", ", ".join(FAMILY_RULES), got=family)
    return int(n1), FAMILY_RULES[family][0](int(n1))


def coupling_1d(space, n: int, k: int) -> np.ndarray:
    """A[j, l] = ∫_0^1 w_j μ_l with w_j the basis of continuous P_k vanishing at 0 and 1 on n uniform
    intervals (the 1D factor of a Q_k trace vanishing on ∂Γ) and μ_l the basis of the 1D ``space``:
    Gauss–Legendre on the union of both breakpoint sets, exact for the degree k + s products."""
    from ...discretization.segment.multipliers import make_space
    from ...discretization.gamma.quadrature import gauss_legendre_01

    w = make_space(np.linspace(0.0, 1.0, n + 1), k, True, True)
    cuts = np.union1d(np.linspace(0.0, 1.0, n + 1), np.asarray(space.breakpoints, float))
    u, wt = gauss_legendre_01(k + int(space.degree) + 2)
    h = np.diff(cuts)
    x = (cuts[:-1, None] + h[:, None] * u[None, :]).ravel()
    q = (h[:, None] * wt[None, :]).ravel()
    return w.evaluate(x).T @ (q[:, None] * space.evaluate(x))


def tensor_kernel_1d(spec, k: int, n1: int, n2: int, rtol: float = 1e-10) -> int:
    """dim ker B1 ∩ ker B2 of a tensor-product space M = M^x ⊗ M^y on G_h = the n2 × n2 trace of Ω2
    against the Q_k traces of n1 × n1 and n2 × n2 rectangle grids: B_i = A_i ⊗ A_i
    (:func:`coupling_1d`), dim M − rank [A1 ⊗ A1; A2 ⊗ A2] (singular values above ``rtol`` times the
    largest). Only for ``spec`` without a ``face_build``."""
    m = spec.build(k, np.linspace(0.0, 1.0, n2 + 1))
    A = [coupling_1d(m, n, k) for n in (n1, n2)]
    stacked = np.vstack([np.kron(a, a) for a in A])
    s = np.linalg.svd(stacked, compute_uv=False)
    return int(stacked.shape[1] - np.sum(s > rtol * s[0]))


def _as_predicted(prediction: str, kernel: int, planar: int) -> bool | None:
    if prediction == PASS:
        return kernel == planar
    if prediction == FAIL:
        return kernel != planar
    return None


def family_kernels(pairs, ks=(1, 2), cases=None, elements=None, model: str | None = None) -> list[dict]:
    """One row per (element, k, pair, case) with a dimension count: dim M, ``planar``, ``tensor``,
    ``kernel_dim``, ``kernel_decision``, ``prediction``, ``as_predicted``. ``cases`` default: every
    registered face space with a count; ``model`` default: the first registered 3D model
    (:func:`~.face_alpha.face_models`); ``elements`` default: all of its elements."""
    from ...models import MODELS, make_model
    from ...solvers.request import MeshOptions
    from ...solvers.side_cache import SideCache
    from ...solvers.infsup import beta_rows_all
    from .alpha import face_models

    model = face_models()[0] if model is None else model

    elements = list(elements or dict(MODELS[model].mesh_options).get("element", ()))
    faces = element_interfaces(model, elements)
    m, cache, rows = make_model(model), SideCache(), []
    for element in elements:
        gamma = faces[element]
        for k in (k for k in ks if gamma.allows(k)):  # HEX20 bodies: k = 2 only
            offered = space_ids(gamma.dim) if cases is None else cases
            ids = [c for c in ids_valid_for(k, offered) if gamma.builds(SPACES[c]) and SPACES[c].dimension is not None]
            for n1, n2 in pairs:
                built = []
                for c in ids:
                    try:
                        planar = planar_kernel(SPACES[c], k, n1, n2, gamma)
                    except InputError:          # a refused space (its weights): no row
                        continue
                    built.append((c, planar))
                found = {r["case"]: r for r in beta_rows_all("structured", k, n1, n2, [c for c, _ in built],
                                                             norms=("L2",), model=m, side_cache=cache,
                                                             mesh=MeshOptions(element=element))}
                for c, planar in built:
                    spec, r = SPACES[c], found[c]
                    product = is_tensor(gamma) and spec.face_build is None
                    tensor = tensor_kernel_bound(spec, k, n1, n2) if product else None
                    exact = tensor_kernel_1d(spec, k, n1, n2) if product else None
                    pred = face_predictions(spec, k, [(n1, n2)], is_tensor(gamma), gamma)["nonmatching"]
                    rows.append(dict(element=element, k=k, N1=n1, N2=n2, case=c, dim_M=r["dim_M"],
                                     planar=planar, tensor=tensor, tensor_1d=exact, kernel_dim=int(r["kernel_dim"]),
                                     kernel_decision=r["kernel_decision"], prediction=pred,
                                     as_predicted=_as_predicted(pred, int(r["kernel_dim"]), planar)))
    return rows


def main(argv=None) -> int:
    """``python -m infsup_contact.study.face.families --N1 5 --k 1 2``: the kernels as CSV on stdout;
    bad input is one line on stderr naming the flag, exit 2, before any row."""
    import pandas as pd

    from ...command_line import OneLineParser, run_study
    from ...models import MODELS
    from .alpha import face_models

    p = OneLineParser(prog="python -m infsup_contact.study.face.families", description=__doc__.split("\n")[0])
    p.add_argument("--family", default="sqrt2", choices=list(FAMILY_RULES))
    p.add_argument("--N1", type=int, nargs="+", default=[5], help="the coarser side; N2 = rule(N1)")
    p.add_argument("--k", type=int, nargs="+", default=[1, 2])
    p.add_argument("--element", nargs="+", default=None, help="mesh elements (default: the model's)")

    def check(args):
        if any(n < 2 for n in args.N1):
            raise InputError("N1", "integers >= 2 (a non-matching pair)", got=args.N1)
        if any(not 1 <= k <= 4 for k in args.k):
            raise InputError("k", "integers in 1..4", got=args.k)
        options = dict(MODELS[face_models()[0]].mesh_options).get("element", ())
        for element in args.element or ():
            if element not in options:
                raise InputError("element", ", ".join(options), got=element)

    def run(args):
        pairs = [family_pair(args.family, n) for n in args.N1]
        pd.DataFrame(family_kernels(pairs, tuple(args.k), elements=args.element)).to_csv(sys.stdout, index=False)

    return run_study(p, argv, check, run)


if __name__ == "__main__":
    raise SystemExit(main())
