"""One contact solve → one tidy row (the columns of ``infsup-contact contact``)."""
from __future__ import annotations

from . import accuracy
from ... import progress
from ...contact.contact import ContactSolution, contact_pair, solve_contact, solve_contact_on
from ...solvers.request import NO_OPTIONS, MeshOptions, check_k
from ...errors import InputError, check_prestress
from ...discretization.spaces.registry import REFERENCE_SPACE, check_case, space_spec
from .scenes import scene as make_scene

def cone_kind(case: str, k: int) -> str:
    """λ_h ≥ 0 "pointwise" (s = 0, 1: nodal positivity is positivity, (5.4)), only "nodal",
    or on "coefficients" of a non-nodal basis (the registry entry's cone)."""
    return space_spec(case).cone(k)


def reference_solution(scene, k: int, n_ref: int, model=None) -> ContactSolution:
    """The reference of a scene without an exact solution: structured N_ref × N_ref, degree
    k + 1, the registry's reference multipliers (stable for every k); ``model`` as in
    :func:`~infsup_contact.contact.contact.solve_contact`."""
    progress.note(f"reference solution (N_ref={n_ref}, degree {k + 1})")
    return solve_contact(scene, REFERENCE_SPACE, k + 1, "structured", n_ref, n_ref, time_floor=False, model=model)


REFERENCE_FORMAT = "infsup-contact reference 1"
"""The ``format`` entry of a saved reference (:func:`save_reference`)."""
_SPACE_FIELDS = ("breakpoints", "degree", "continuous", "vanish_at_ends", "dofs", "dim")


def save_reference(path, ref: ContactSolution) -> None:
    """Write what the error measures need of a reference atomically, as a NumPy ``.npz`` of plain
    arrays — never a pickle, which would run any code a planted file carries when read: M_h (its
    fields), λ_h, (c1, c2) and, per side, u_h and ∇u_h at the reference's own quadrature points
    with their weights (:func:`~.accuracy.reference_quadrature`; the error measures use u_h there
    only). The workflow solves the membranes reference once per k and every contact job of that
    k reads it (:func:`load_reference`)."""
    import io

    import numpy as np

    from ...discretization.segment.multipliers import SegmentSpace
    from ...io import write_bytes_atomic
    from .accuracy import reference_quadrature

    if type(ref.space) is not SegmentSpace:
        raise InputError("reference", "a reference whose M_h is a plain SegmentSpace", got=type(ref.space).__name__)
    arrays = {"format": np.array(REFERENCE_FORMAT), "lam": np.asarray(ref.lam, float),
              "c": np.asarray(ref.c, float)}
    for name in _SPACE_FIELDS:
        arrays[f"space_{name}"] = np.asarray(getattr(ref.space, name))
    if ref.space.local_coefficients is not None:
        arrays["space_local_coefficients"] = np.asarray(ref.space.local_coefficients, float)
    for side, (xy, w, u, grad) in enumerate(reference_quadrature(ref)):
        for key, value in (("xy", xy), ("w", w), ("u", u), ("grad", grad)):
            arrays[f"side{side}_{key}"] = np.asarray(value, float)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    write_bytes_atomic(path, buf.getvalue())


def load_reference(path):
    """The reference written by :func:`save_reference` (attributes ``space``, ``lam``, ``c``,
    and its u as the error measures' samples), read with ``allow_pickle=False``.

    Raises
    ------
    InputError
        ``reference``, one line naming the file: missing, not an ``.npz`` of this format (a
        pickle is refused unread: its code never runs), an entry missing, of the wrong type or
        shape, or not finite."""
    import types
    import zipfile

    import numpy as np

    from ...discretization.segment.multipliers import SegmentSpace
    from .accuracy import with_reference_quadrature

    allowed = f"a reference written by save_reference ({REFERENCE_FORMAT!r}: an .npz of plain arrays, no pickle)"

    def bad(problem):
        return InputError("reference", allowed, got=f"{path}: {problem}")

    try:
        data = np.load(path, allow_pickle=False)  # a pickle: ValueError before a byte of it is unpickled
        if not isinstance(data, np.lib.npyio.NpzFile):
            raise bad("a single array, not an .npz archive")
        with data:
            entries = {key: data[key] for key in data.files}  # an object array: ValueError, not unpickled
    except FileNotFoundError:
        raise bad("no such file") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        reason = " ".join(str(err).split())[:120]
        raise bad(f"not readable as plain arrays ({reason})") from None
    if str(entries.get("format", "")) != REFERENCE_FORMAT:
        raise bad(f"format {str(entries.get('format', 'missing'))[:60]!r}")

    def get(key, ndim, kind="f"):
        if key not in entries:
            raise bad(f"no entry {key}")
        a = entries[key]
        if a.ndim != ndim or a.dtype.kind not in (kind + ("iu" if kind == "f" else "")):
            raise bad(f"entry {key} has dtype {a.dtype} and {a.ndim} dimensions")
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            raise bad(f"entry {key} is not finite")
        return a

    bp, dofs = get("space_breakpoints", 1), get("space_dofs", 2, "i")
    degree, dim = int(get("space_degree", 0, "i")), int(get("space_dim", 0, "i"))
    lam, c = get("lam", 1).astype(float), get("c", 1).astype(float)
    coeff = get("space_local_coefficients", 3).astype(float) if "space_local_coefficients" in entries else None
    if (len(bp) < 2 or dofs.shape != (len(bp) - 1, degree + 1) or len(lam) != dim or dofs.max() >= dim
            or len(c) != 2 or (coeff is not None and coeff.shape != (len(bp) - 1, degree + 1, degree + 1))):
        raise bad("entries of inconsistent shapes")
    space = SegmentSpace(bp.astype(float), degree, bool(get("space_continuous", 0, "b")),
                            bool(get("space_vanish_at_ends", 0, "b")), dofs.astype(int), dim, coeff)
    quadrature = []
    for side in range(2):
        xy, w, u, grad = (get(f"side{side}_{k}", n) for k, n in (("xy", 2), ("w", 1), ("u", 1), ("grad", 2)))
        if xy.shape[1] != 2 or grad.shape != xy.shape or not len(w) == len(u) == len(xy):
            raise bad(f"entries of side {side} of inconsistent shapes")
        quadrature.append((xy.astype(float), w.astype(float), u.astype(float), grad.astype(float)))
    ref = types.SimpleNamespace(space=space, lam=lam, c=tuple(c), u=())
    return with_reference_quadrature(ref, quadrature)


def contact_row(scene_name: str, case: str, k: int, family: str, n1: int, n2: int,
                c1: float = 1.0, c2: float = 1.0, reference: ContactSolution | None = None,
                n_ref: int = 64, time_floor: bool = True, scene_params: dict | None = None, model=None,
                mesh: MeshOptions = NO_OPTIONS) -> dict:
    """Solve one instance of (4.1) and measure it; errors vs exact (manufactured) or reference."""
    return contact_rows(scene_name, [case], k, family, n1, n2, c1, c2, reference, n_ref,
                        time_floor, scene_params, model=model, mesh=mesh)[0]


def contact_rows(scene_name: str, cases, k: int, family: str, n1: int, n2: int,
                 c1: float = 1.0, c2: float = 1.0, reference: ContactSolution | None = None,
                 n_ref: int = 64, time_floor: bool = True, scene_params: dict | None = None,
                 model=None, mesh: MeshOptions = NO_OPTIONS) -> list[dict]:
    """:func:`contact_row` for several multiplier cases on one mesh pair, which is meshed,
    factorized and loaded once (:func:`~infsup_contact.contact.contact.contact_pair`)."""
    check_k(k)
    for case in cases:
        check_case(case, k)
    for key, c in (("c1", c1), ("c2", c2)):
        check_prestress(key, c)
    sc = make_scene(scene_name, c1=c1, c2=c2, **(scene_params or {}))
    if not sc.has_exact:
        reference = reference or reference_solution(sc, k, n_ref, model)
    progress.note("the two sides: mesh, stiffness, factorization")
    pair = contact_pair(sc, k, family, n1, n2, model=model, mesh=mesh)
    rows = []
    for case in progress.steps(cases, "space") if len(cases) > 1 else cases:
        progress.note("contact solve")
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
