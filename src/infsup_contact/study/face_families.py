"""Kernels on the non-matching families of the face (issue 28, item 1): the √2 pairs in 3D.

The 2D study's families (:mod:`~infsup_contact.discretization.series`) change the overlap pattern
of the two traces with N; ``sqrt2`` (round(√2 n)) makes the two grids share no interior line when
gcd(N1, N2) = 1 (5:7, 7:10), so the common coarsening of the traces is the single cell and
dim(W1 ∩ W2) = 0 on rectangles (:meth:`~infsup_contact.discretization.square.Square.trace_sum_dimension`).
On the face Ω2 is the finer side, N2 = round(√2 N1) (:mod:`infsup_contact.config_face`).

For every space, k and element on such a pair this compares three numbers
(:mod:`.face_claims`' reasoning):

* ``planar`` — the dimension argument max(dim M − dim(W1 + W2), 0) (:func:`~.face_claims.planar_kernel`),
  a lower bound of dim ker(B A⁻¹ Bᵀ) on any face;
* ``tensor`` — on rectangle faces, for the tensor-product spaces, 2 a1 a2 − min(a1, a2)² with the 1D
  counts a_i (:func:`~.face_claims.tensor_kernel_bound`), also a lower bound (None elsewhere);
* ``kernel_dim`` — the numerical count (:func:`~infsup_contact.solvers.infsup.beta_rows_all`, L²
  Gram: the kernel of the pencil does not depend on the SPD Gram), with its decision
  (``clear`` or ``close``).

``prediction`` is :func:`~.face_claims.face_predictions`' verdict of "kernel = planar count" on this
pair alone (PASS, FAIL where the tensor bound exceeds the count, ``finding`` where only lower bounds
are known); ``as_predicted`` whether the numbers bear it out.

Run: ``python -m infsup_contact.study.face_families --N1 5 --k 1 2`` (CSV on stdout).
"""
from __future__ import annotations

import argparse
import sys

from ..discretization.registry import SPACES, ids_valid_for
from ..discretization.series import FAMILY_RULES
from ..errors import InputError
from .claims import FAIL, PASS
from .face_claims import element_interfaces, face_predictions, is_tensor, planar_kernel, tensor_kernel_bound


def family_pair(family: str, n1: int) -> tuple:
    """(N1, N2 = rule(N1)): Ω2 the finer side (module docstring); InputError for an unknown family."""
    if family not in FAMILY_RULES:
        raise InputError("family", ", ".join(FAMILY_RULES), got=family)
    return int(n1), FAMILY_RULES[family][0](int(n1))


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
    from ..models import MODELS, make_model
    from ..models.side_cache import SideCache
    from ..solvers.infsup import beta_rows_all
    from .face_alpha import face_models

    model = face_models()[0] if model is None else model

    elements = list(elements or dict(MODELS[model].mesh_options).get("element", ()))
    faces = element_interfaces(model, elements)
    m, cache, rows = make_model(model), SideCache(), []
    for element in elements:
        gamma = faces[element]
        for k in ks:
            ids = [c for c in ids_valid_for(k, cases, gamma_dim=2) if gamma.builds(SPACES[c])
                   and SPACES[c].dimension is not None]
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
                                                             element=element)}
                for c, planar in built:
                    spec, r = SPACES[c], found[c]
                    tensor = (tensor_kernel_bound(spec, k, n1, n2)
                              if is_tensor(gamma) and spec.face_build is None else None)
                    pred = face_predictions(spec, k, [(n1, n2)], is_tensor(gamma), gamma)["nonmatching"]
                    rows.append(dict(element=element, k=k, N1=n1, N2=n2, case=c, dim_M=r["dim_M"],
                                     planar=planar, tensor=tensor, kernel_dim=int(r["kernel_dim"]),
                                     kernel_decision=r["kernel_decision"], prediction=pred,
                                     as_predicted=_as_predicted(pred, int(r["kernel_dim"]), planar)))
    return rows


def main(argv=None) -> None:
    import pandas as pd

    p = argparse.ArgumentParser(prog="python -m infsup_contact.study.face_families",
                                description=__doc__.split("\n")[0])
    p.add_argument("--family", default="sqrt2", choices=list(FAMILY_RULES))
    p.add_argument("--N1", type=int, nargs="+", default=[5], help="the coarser side; N2 = rule(N1)")
    p.add_argument("--k", type=int, nargs="+", default=[1, 2])
    p.add_argument("--element", nargs="+", default=None, help="mesh elements (default: the model's)")
    args = p.parse_args(argv)
    if any(n < 2 for n in args.N1):
        raise InputError("N1", "integers >= 2 (a non-matching pair)", got=args.N1)
    if any(not 1 <= k <= 4 for k in args.k):
        raise InputError("k", "integers in 1..4", got=args.k)
    pairs = [family_pair(args.family, n) for n in args.N1]
    frame = pd.DataFrame(family_kernels(pairs, tuple(args.k), elements=args.element))
    frame.to_csv(sys.stdout, index=False)


if __name__ == "__main__":
    main()
