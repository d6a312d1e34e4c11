"""One contact solve → one tidy row (the columns of ``infsup-contact contact``)."""
from __future__ import annotations

from . import accuracy
from ..solvers.contact import ContactSolution, contact_pair, solve_contact, solve_contact_on
from ..errors import InputError, check_prestress
from ..discretization.registry import REFERENCE_SPACE, check_case, space_spec
from .scenes import scene as make_scene

def cone_kind(case: str, k: int) -> str:
    """λ_h ≥ 0 "pointwise" (s = 0, 1: nodal positivity is positivity, (5.4)), only "nodal",
    or on "coefficients" of a non-nodal basis (the registry entry's cone)."""
    return space_spec(case).cone(k)


def reference_solution(scene, k: int, n_ref: int, model=None) -> ContactSolution:
    """The reference of a scene without an exact solution: structured N_ref × N_ref, degree
    k + 1, the registry's reference multipliers (stable for every k); ``model`` as in
    :func:`~infsup_contact.solvers.contact.solve_contact`."""
    return solve_contact(scene, REFERENCE_SPACE, k + 1, "structured", n_ref, n_ref, time_floor=False, model=model)


def save_reference(path, ref: ContactSolution) -> None:
    """Write what the error measures need of a reference (u_h as NGSolve grid functions,
    which pickle with their mesh and space; M_h; λ_h) atomically, without the factorized
    sides: the workflow solves the membranes reference once per k and every contact job of
    that k reads it (:func:`load_reference`)."""
    import pickle
    import types

    import numpy as np

    from ..io import write_bytes_atomic

    light = types.SimpleNamespace(u=list(ref.u), space=ref.space, lam=np.asarray(ref.lam), c=tuple(ref.c))
    write_bytes_atomic(path, pickle.dumps(light, protocol=pickle.HIGHEST_PROTOCOL))


def load_reference(path):
    """The reference written by :func:`save_reference` (attributes u, space, lam, c)."""
    import pickle

    with open(path, "rb") as fh:
        return pickle.load(fh)


def contact_row(scene_name: str, case: str, k: int, family: str, n1: int, n2: int,
                c1: float = 1.0, c2: float = 1.0, reference: ContactSolution | None = None,
                n_ref: int = 64, time_floor: bool = True, scene_params: dict | None = None, model=None,
                **mesh_kwargs) -> dict:
    """Solve one instance of (4.1) and measure it; errors vs exact (manufactured) or reference."""
    return contact_rows(scene_name, [case], k, family, n1, n2, c1, c2, reference, n_ref,
                        time_floor, scene_params, model=model, **mesh_kwargs)[0]


def contact_rows(scene_name: str, cases, k: int, family: str, n1: int, n2: int,
                 c1: float = 1.0, c2: float = 1.0, reference: ContactSolution | None = None,
                 n_ref: int = 64, time_floor: bool = True, scene_params: dict | None = None,
                 model=None, **mesh_kwargs) -> list[dict]:
    """:func:`contact_row` for several multiplier cases on one mesh pair, which is meshed,
    factorized and loaded once (:func:`~infsup_contact.solvers.contact.contact_pair`)."""
    if not 1 <= k <= 4:
        raise InputError("k", "an integer in 1..4", got=k)
    for case in cases:
        check_case(case, k)
    for key, c in (("c1", c1), ("c2", c2)):
        check_prestress(key, c)
    sc = make_scene(scene_name, c1=c1, c2=c2, **(scene_params or {}))
    if not sc.has_exact:
        reference = reference or reference_solution(sc, k, n_ref, model)
    pair = contact_pair(sc, k, family, n1, n2, model=model, **mesh_kwargs)
    rows = []
    for case in cases:
        sol = solve_contact_on(pair, case, time_floor=time_floor)
        rows.append(dict(scene=scene_name, case=case, k=k, p=getattr(sc, "p", float("nan")),
                         q=getattr(sc, "q", float("nan")), family=family, N1=n1, N2=n2, c1=c1, c2=c2,
                         **_measures(sol, sc, reference, cone_kind(case, k))))
    return rows


def _measures(sol: ContactSolution, sc, reference, cone: str) -> dict:
    """The columns of a row that measure the solution: errors vs the exact solution
    (manufactured scenes) or the reference, the active-set statistics, the timings."""
    if sc.has_exact:
        energy, l2 = accuracy.energy_and_l2_errors(sol, sc)
        lam_l2 = accuracy.lambda_l2_error(sol, sc.lam, kinks=[sc.a])
        lam_h = accuracy.lambda_hm12_error(sol, sc.lam)
        cs = accuracy.contact_set_error(sol, sc.contact_set)
    else:
        energy, l2 = accuracy.energy_and_l2_vs_reference(sol, reference)
        lam_l2, lam_h = accuracy.lambda_errors_vs_reference(sol, reference)
        cs = accuracy.contact_set_error_vs_reference(sol, reference)
    p = sol.pdas
    return dict(
        ndof=sol.ndof, dim_M=sol.space.dim, cone=cone, iterations=p.iterations,
        energy_error=energy, l2_error=l2, lambda_l2_error=lam_l2, lambda_hm12_error=lam_h,
        contact_set_error=cs, complementarity=p.complementarity, min_gap=p.min_gap,
        min_lambda=p.min_lambda, min_lambda_pointwise=accuracy.lambda_min_pointwise(sol),
        max_penetration=accuracy.max_penetration(sol),
        lambda_tv=accuracy.lambda_total_variation(sol), nonunique=bool(p.nonunique),
        kernel_dim=int(p.kernel_dim_K), t_solve=sol.t_solve, t_linear_solve=sol.t_linear_solve)
