"""This suite's own systems in the foreign layout: A, B, G per level and a manifest.

For a registered space on the two-body pair (N1, N2): A = diag(K_1, K_2) on the free dofs of
both bodies at unit material scale (Γ dofs last in each block, as the model seam gives them),
B = [−B_1 0 | B_2 0] with the couplings B_i on the Γ columns, G the Gram matrix of the
multiplier norm (H^{-1/2}_00(Γ) by the log kernel, or L²(Γ)). Then B A⁻¹ Bᵀ = Σ_i B_i X_i B_iᵀ
exactly as ``beta`` forms it, so ``verdict --system`` on an export must reproduce
``verdict --case`` (``tests/systems/test_systems_roundtrip.py``). h = 1/N2 as in ``verdict --case``.

With ``norm="H"`` :func:`suite_levels` writes what a producer writes (``norm: H``): Γ
(``gamma``), per level the ``multipliers`` description (:mod:`.multiplier_basis`; the helper
form of a registered Lagrange or dual space, else the general form) and G = the L² mass; the
H^{-1/2}_00 Gram is then assembled by the reader. A space the description cannot express (the
face's cellwise element spaces, P_s on triangles) keeps ``norm: given`` with G = the H Gram.
A face space's rows are reordered to the description's default, row i + n_x j for ψ_i(x) ψ_j(y).
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import yaml

from .. import progress
from ..errors import InputError
from ..io import write_atomic, write_bytes_atomic
from .hb_petsc import petsc_binary_bytes

EXPORT_FORMATS = {"mtx": ".mtx", "npz": ".npz", "petsc": ".petsc"}


def suite_system(case: str, k: int, n1: int, n2: int, family: str = "structured", norm: str = "H",
                 multiplier_mesh: str = "omega2", model=None, mesh=None, gamma=None):
    """(A, B, G) of ``case`` on the pair (N1, N2) of ``model`` (default: membranes) with the mesh
    options ``mesh`` (a :class:`~infsup_contact.solvers.request.MeshOptions`; None: the builder's
    defaults) on the request's Γ ``gamma`` (:func:`~infsup_contact.solvers.request.resolve_gamma`;
    None: the model's flat one)."""
    A, B, space, gamma, _ = _suite_parts(case, k, n1, n2, family, multiplier_mesh, model, mesh, gamma)
    G, _ = gamma.gram(space, norm)
    return A, B, np.asarray(G, float)


def _suite_parts(case, k, n1, n2, family, multiplier_mesh, model, mesh=None, gamma=None):
    """(A, B, the multiplier space, Γ, the two side operators) of ``case`` on the pair (N1, N2)."""
    from ..discretization.spaces import registry
    from ..discretization.gamma.coupling import coupling_matrix
    from ..models.membranes import MEMBRANES
    from ..solvers.request import NO_OPTIONS
    from ..solvers.side_cache import SideCache

    sides = SideCache().pair(MEMBRANES if model is None else model, family, k, n1, n2,
                             NO_OPTIONS if mesh is None else mesh, gamma)
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), multiplier_mesh)
    space = registry.case_space(case, k, g_h, gamma)
    progress.note("couplings B_1, B_2")
    blocks = []
    for sign, side in zip((-1.0, 1.0), sides):
        Bi = coupling_matrix(side.trace, space, k)
        full = np.zeros((Bi.shape[0], side.ndof))
        full[:, side.ndof - Bi.shape[1]:] = sign * Bi
        blocks.append(sp.csr_matrix(full))
    A = sp.block_diag([s.stiffness for s in sides], format="csr")
    return A, sp.hstack(blocks, format="csr"), space, gamma, sides


def suite_levels(case: str, k: int, ns, offset: int = 0, family: str = "structured", norm: str = "H",
                 multiplier_mesh: str = "omega2", model=None, mesh=None, gamma=None) -> tuple:
    """(levels, manifest norm, gamma) of ``case`` on N1 = N + offset, N2 = N for N in ``ns``, as
    :func:`write_system` takes them (module docstring: ``norm: H`` with the description where the
    space has one; ``mesh``, ``gamma`` as in :func:`suite_system`)."""
    from ..discretization.spaces.registry import space_spec

    spec, levels, described = space_spec(case), [], norm == "H"
    parts = [_suite_parts(case, k, n + offset, n, family, multiplier_mesh, model, mesh, gamma)
             for n in progress.steps(ns, "level", lambda n: f"N1={n + offset} N2={n}" if offset else f"N={n}")]
    described = described and all(description(spec, p[2]) is not None for p in parts)
    for n, (A, B, space, gamma, sides) in progress.steps(list(zip(ns, parts)), "Gram of level", lambda p: f"N={p[0]}"):
        if not described:
            G, _ = gamma.gram(space, norm)
            levels.append((1.0 / n, A, B, np.asarray(G, float)))
            continue
        mult, order = description(spec, space)
        G, _ = gamma.gram(space, "L2")
        levels.append((1.0 / n, A, B[order], np.asarray(G, float)[np.ix_(order, order)], mult,
                       trace_forms(sides, k)))
    if described:
        face = parts[0][2].factors is not None
        gamma = {"shape": "rectangle", "size": [1.0, 1.0]} if face else {"shape": "segment", "length": 1.0}
        return levels, "H", gamma
    return levels, "given" if norm == "H" else "L2", None


def description(spec, space):
    """(the ``multipliers`` mapping of ``space``, the order of its basis functions as the
    description counts them) or None where it has none (module docstring)."""
    from ..discretization.face.spaces.tensor import FaceSpace
    from ..discretization.segment.multipliers import SegmentSpace

    if isinstance(space, SegmentSpace):
        return segment_form(spec, space), np.arange(space.dim)
    if type(space) is FaceSpace and all(isinstance(f, SegmentSpace) for f in space.factors):
        sx, sy = space.factors
        i, j = np.divmod(np.arange(space.dim), sy.dim)  # FaceSpace's row i n_y + j; counted i + n_x j
        return {"x": segment_form(spec, sx), "y": segment_form(spec, sy)}, np.argsort(i + sx.dim * j)
    return None


def trace_forms(sides, k: int):
    """The ``traces`` of the two bodies (:mod:`.mortar_distance`): on the segment the general form
    of each side's Γ-dof basis (its values at the equispaced Lagrange nodes of every trace
    interval: the coefficients of those shapes), ``columns`` = the dof of A (Γ dofs last in each
    block, in the trace's order). On a hexahedral face at k = 1 the bilinear hats, the tensor
    product of the 1D hats (:func:`_face_trace_forms`); None on other faces (NGSolve's Q_k, k ≥ 2,
    and P_k bases are not tensor products of 1D Lagrange shapes)."""
    from ..discretization.segment.multipliers import reference_nodes

    if sides[0].trace.gamma.dim != 1:
        return _face_trace_forms(sides) if k == 1 and sides[0].trace.gamma.cell == "quad" else None
    out, offset = [], 0
    for sign, side in zip((-1, 1), sides):
        tr = side.trace
        if not len(tr.gamma_dofs):  # a body with no free dof on Γ (N = 1, k = 1) meets no multiplier
            offset += side.ndof
            continue
        x = np.asarray(tr.breakpoints, float)
        nodes = (x[:-1, None] + np.diff(x)[:, None] * reference_nodes(k)[None, :])  # (N, k + 1)
        V = tr.gamma.trace_basis(tr, nodes.ravel()).reshape(len(x) - 1, k + 1, -1)  # (N, node, Γ dof)
        dofs, coef = -np.ones((len(x) - 1, k + 1), int), np.zeros((len(x) - 1, k + 1, k + 1))
        for e in range(len(x) - 1):
            live = np.flatnonzero(np.any(V[e] != 0.0, axis=0))  # a degree-k function zero at k + 1 nodes is 0
            dofs[e, :len(live)] = live
            coef[e, :len(live)] = V[e][:, live].T
        first = offset + side.ndof - len(tr.gamma_dofs)
        out.append({"breakpoints": x.tolist(), "degree": int(k), "dofs": dofs.tolist(), "coefficients": coef.tolist(),
                    "columns": list(range(first, first + len(tr.gamma_dofs))), "sign": sign})
        offset += side.ndof
    return out or None


def _face_trace_forms(sides) -> list:
    """The bilinear hats of each side's face trace as {x, y} Lagrange P_1 forms (ends dropped: Γ's
    boundary is fixed); ``columns[i + n_x j]`` = the dof of A whose basis function is 1 at the
    node (x_{i+1}, y_{j+1}), read off the trace basis there (it must be a permutation)."""
    out, offset = [], 0
    for sign, side in zip((-1, 1), sides):
        tr = side.trace
        if not len(tr.gamma_dofs):  # no free dof on Γ (one cell per direction at k = 1)
            offset += side.ndof
            continue
        xs, ys = (np.asarray(g, float) for g in (tr.partition.xs, tr.partition.ys))
        X, Y = np.meshgrid(xs[1:-1], ys[1:-1], indexing="xy")  # node i + n_x j at row j, column i
        V = np.asarray(tr.gamma.trace_basis(tr, np.column_stack([X.ravel(), Y.ravel()])))
        p = np.argmax(np.abs(V), axis=1)
        if V.shape[0] != V.shape[1] or not np.allclose(V[np.arange(len(p)), p], 1.0, atol=1e-12) \
                or len(np.unique(p)) != len(p) or not np.allclose(np.abs(V).sum(axis=1), 1.0, atol=1e-12):
            return None  # not the nodal hats: no description written
        first = offset + side.ndof - len(tr.gamma_dofs)
        axis = [{"basis": "lagrange", "degree": 1, "breakpoints": g.tolist(), "ends": "drop"} for g in (xs, ys)]
        out.append({"x": axis[0], "y": axis[1], "columns": (first + p).tolist(), "sign": sign})
        offset += side.ndof
    return out or None


def segment_form(spec, space) -> dict:
    """The helper form of a registered Lagrange / dual space (``spec.lagrange``, ``spec.dual``) when
    it builds exactly ``space``; else the general form (breakpoints, degree, dofs, coefficients)."""
    from .multiplier_basis import _segment

    x = [float(v) for v in space.breakpoints]
    if spec is not None and spec.lagrange is not None:
        continuous, vanish = spec.lagrange
        form = {"basis": "dual" if spec.dual else ("lagrange" if continuous else "discontinuous"),
                "degree": int(space.degree), "breakpoints": x}
        if vanish and (continuous or space.degree > 0):
            form["ends"] = "drop"
        try:
            built, _ = _segment("export", "multipliers", form, Path("."), 1.0, face=False)
        except InputError:
            built = None
        if built is not None and _same(built, space):
            return form
    form = {"breakpoints": x, "degree": int(space.degree), "dofs": space.dofs.tolist()}
    if space.local_coefficients is not None:
        form["coefficients"] = np.asarray(space.local_coefficients, float).tolist()
    return form


def _same(a, b) -> bool:
    """Whether two 1D spaces have the same partition, numbering and local basis."""
    ca = a.local_coefficients
    cb = b.local_coefficients
    return (np.array_equal(a.breakpoints, b.breakpoints) and np.array_equal(a.dofs, b.dofs)
            and (ca is None) == (cb is None) and (ca is None or np.array_equal(ca, cb)))


def matrix_bytes(mat, fmt: str) -> bytes:
    """``mat`` serialized as ``fmt`` (mtx: MatrixMarket coordinate/array via scipy.io.mmwrite;
    npz: scipy.sparse.save_npz, or numpy.savez of one array for a dense matrix; petsc: PETSc
    binary AIJ, :func:`~.hb_petsc.petsc_binary_bytes`)."""
    buf = io.BytesIO()
    if fmt == "mtx":
        import scipy.io

        scipy.io.mmwrite(buf, mat, precision=17)
    elif fmt == "npz":
        if sp.issparse(mat):
            sp.save_npz(buf, sp.csr_matrix(mat), compressed=True)
        else:
            np.savez_compressed(buf, G=np.asarray(mat))
    else:
        return petsc_binary_bytes(mat)
    return buf.getvalue()


def write_system(directory, levels, fmt: str, name: str, norm: str = "given", known_kernel: int = 0,
                 gamma: dict | None = None, written: list | None = None) -> Path:
    """Write each level's A, B, G as ``{A,B,G}<i>.<ext>`` and ``levels.yaml`` (atomically);
    ``levels``: (h, A, B, G[, multipliers[, traces]]) coarse to fine (G None: not written;
    ``multipliers`` a mapping and ``traces`` a list, with ``gamma`` for ``norm: H``). Returns the
    manifest's path; ``written`` (a list), if given, receives the names of the files written.

    The manifest is for people too: a level without a description is one short line
    ``- {h: …, A: …, B: …, G: …}``; a described level is a block, and each of its arrays longer
    than :data:`INLINE_MAX` numbers is a ``.npy`` file beside the matrices
    (``level<i>_<keys>.npy``, exact float64 / int64), which the manifest reader takes in place of
    the inline list (:mod:`.multiplier_basis`)."""
    directory = Path(directory)
    ext = EXPORT_FORMATS[fmt]
    written = [] if written is None else written
    lines = [f"name: {name}", f"norm: {norm}"] + ([f"known_kernel: {known_kernel}"] if known_kernel else [])
    if gamma is not None:  # a few numbers: one line, {shape: segment, length: 1.0}
        lines.append("gamma: " + yaml.safe_dump(gamma, default_flow_style=True, sort_keys=False).strip())
    lines.append("levels:")
    for i, (h, A, B, G, *described) in progress.steps(list(enumerate(levels)), "writing level",
                                                      lambda lv: f"h={lv[1][0]:g}"):
        names = {}
        for key, mat in (("A", A), ("B", B), ("G", G)):
            if mat is not None:
                names[key] = f"{key}{i}{ext}"
                write_bytes_atomic(directory / names[key], matrix_bytes(mat, fmt))
                written.append(names[key])
        mult, traces = (list(described) + [None, None])[:2]
        if not mult and not traces:
            lines.append(f"  - {{h: {h!r}" + "".join(f", {key}: {file}" for key, file in names.items()) + "}")
            continue
        entry = {"h": h, **names}
        for key, value in (("multipliers", mult), ("traces", traces)):
            if value:
                entry[key] = _side_files(directory, f"level{i}_{key}", value, written)
        block = yaml.dump([entry], Dumper=_ManifestDumper, sort_keys=False, width=100, allow_unicode=True)
        lines += ["  " + line for line in block.rstrip().splitlines()]
    path = directory / "levels.yaml"
    write_atomic(path, "\n".join(lines) + "\n")
    written.append(path.name)
    return path


INLINE_MAX = 12
"""Longest array (in numbers) written inline in a manifest; a longer one is a ``.npy`` side file."""


def _side_files(directory: Path, stem: str, value, written: list):
    """``value`` (a description) with every numeric array longer than :data:`INLINE_MAX` numbers
    written to ``<stem>_<key>.npy`` and replaced by that file name."""
    if isinstance(value, dict):
        return {k: _side_files(directory, f"{stem}_{k}", v, written) for k, v in value.items()}
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        return [_side_files(directory, f"{stem}_{j}", v, written) for j, v in enumerate(value)]
    if isinstance(value, list):
        arr = np.asarray(value)
        if arr.size > INLINE_MAX and arr.dtype.kind in "iuf":
            name = f"{stem}.npy"
            buf = io.BytesIO()
            np.save(buf, arr.astype(np.int64 if arr.dtype.kind in "iu" else np.float64), allow_pickle=False)
            write_bytes_atomic(directory / name, buf.getvalue())
            written.append(name)
            return name
    return value


class _ManifestDumper(yaml.SafeDumper):
    """Block style, with a short list of numbers on one line (``[0.0, 0.5, 1.0]``)."""


def _short_lists_inline(dumper, data):
    flow = len(data) <= INLINE_MAX and all(isinstance(v, (int, float, str)) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_ManifestDumper.add_representer(list, _short_lists_inline)
