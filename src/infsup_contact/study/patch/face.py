"""The 3D contact patch test on the face Γ = (0,1)²×{1}.

Two scalar bodies, Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2), −c_i Δu_i = 0, on non-matching
structured meshes (N1 ≠ N2 cells per direction on Γ): u1 = 0 on Ω1's far face z = 0,
u2 = −δ on Ω2's far face z = 2, the four lateral faces of each body natural
(∂u_i/∂n = 0), frictionless contact on Γ with b(v, μ) = ∫_Γ (v2 − v1) μ
(:mod:`infsup_contact.models.contract`, n = e_z). As Tribol's ``mfem_mortar_lm_patch``:
a uniform pressure on non-matching faces, reproduced exactly iff M_h holds it.

**Exact solution.** Try u_i = u_i(z): the lateral conditions hold, −c_i u_i'' = 0 makes u_i
affine, u1 = a z and u2 = −δ + b (z − 2). With contact active on Γ (zero gap), u1(1) = u2(1)
gives a = −δ − b, and equilibrium of the fluxes on Γ (λ = −c1 u1' = −c2 u2': the multiplier
enters A_1 u_1 = F_1 − B_1ᵀλ and A_2 u_2 = F_2 + B_2ᵀλ) gives c1 a = c2 b. Hence

    a = −δ c2/(c1 + c2),   λ = −c1 a = δ / (1/c1 + 1/c2) > 0,
    u1 = −(λ/c1) z,   u2 = −δ + (λ/c2)(2 − z),

(c1 = c2 = 1: λ = δ/2, u1 = u2 = −(δ/2) z). λ > 0 and the gap u2 − u1 = 0 on Γ satisfy the
complementarity λ ≥ 0, g ≥ 0, λ g = 0, and the solution of the (monotone) contact problem is
unique in u, so this is it.

**Prediction (stated before the run).** u_i is linear, so it lies in every V_{h,i} (Q_k on
hexahedra, P_k on tetrahedra, k ≥ 1), and its traces coincide: B(u2 − u1) = 0. If the
constant λ lies in M_h, (u, λ) satisfies the discrete system exactly (B_iᵀ(λ·1) are the
consistent nodal forces of the uniform flux, A_i u_i = F_i ∓ B_iᵀ(λ·1) by Green's formula),
and its coefficients λ·(coefficients of 1) are ≥ 0 in the cone of every registered space
(a nodal basis of 1 has coefficients 1; the dual bases are partitions of unity where they
hold 1). So the test passes — u_h = u and λ_h = λ to round-off, whatever the seams of the
non-matching traces — iff 1 ∈ M_h, computed on the face space itself
(:func:`~infsup_contact.discretization.gamma.constants.spans_constants`; the registry's
``SpaceSpec.contains_constants(k)`` is the segment's answer and differs for DUAL at k = 1 on
the six-tetrahedra faces, whose two corner triangles have no vertex off ∂Γ) (the face space
is the tensor product of the 1D one, :mod:`~infsup_contact.discretization.face.spaces.tensor`, and
1 ⊗ 1 = 1). T3 (Q_k vanishing on ∂Γ) fails. A kernel of K (λ_h not unique) leaves u_h unique;
the PDAS's representative (minimum norm, :mod:`infsup_contact.contact.pdas`) need not be the
constant, so a space with a kernel may reproduce u but not λ: ``kernel_dim`` and ``nonunique``
are reported with each row. With natural lateral faces the traces do not vanish on ∂Γ, so
the spaces' kernel on clamped traces (R5.2's boundary modes) has no counterpart here.

**Outcome** (k = 1, 2, 3; hexahedra and tetrahedra; N1:N2 = 4:5 and 7:8; G_h = trace of Ω2;
exploratory runs outside the DAG, the test ``tests/study/test_face_patch.py`` pins the rule):
as predicted in all 76 rows — every space holding the constants reproduces λ to 1e-14..5e-11
(R5.4 at k = 3 the largest) and u to ≤ 2e-14 of δ; T3 fails (λ error ≥ 1, at ∂Γ where it
vanishes, u error ~1e-2 δ). No row has a kernel (``kernel_dim`` 0, ``nonunique`` False). On
G_h = the union of both traces (``multiplier_mesh="union"``) R5.2, R5.4, DUAL and DUAL-ALL
have kernels (k = 2, 4:5: 96, 70, 48, 96 modes): u_h stays exact to round-off but the PDAS's
minimum-norm λ_h is not the constant (errors 0.1–1.3), so ``passes`` is False there although
1 ∈ M_h; T4 and T5 (no kernel) still pass.

**In the DAG** (rule ``face_study_job``, :func:`face_patch_table`; ledger claims
:mod:`.claims.membranes3d_studies`): at k = 1 on tetrahedra DUAL fails (λ error 1, at the corner triangles):
the boundary-modified TRI3 dual has no live node on a corner triangle whose three vertices lie
on ∂Γ, so its face space lacks the constants although the 1D ``contains_constants`` (this
module's ``predicted`` column) holds; the ledger's prediction checks 1 ∈ M_h on the space the
face builds (``face_contains_constants``) and predicts that failure. R5.4 at k = 1 on
tetrahedra has a kernel (1 and 2 modes on 4:5, 7:8) and still passes.

**HEX20 bodies** (``element="hex20"``, k = 2 only: :mod:`infsup_contact.models.hex20`; every space
the QUAD8 face builds, ``Interface.builds``). u is linear, so it lies in serendipity Q2 and the
argument above holds unchanged: the test passes iff 1 ∈ M_h (``spans_constants`` on the face
space) and K has no kernel. *Prediction* (written before the table was run): T3, Q8 and LIN0-Q8
vanish on ∂Γ and fail; T4, T5, DUAL, DUAL-ALL, TDUAL-Q8, Q8-ALL, DISC-P1, R5.2, R5.4 hold 1 and
pass where K has no kernel. A Petrov–Galerkin pair (PGLIN0-Q8, PGLIN-Q8: two bases) has no
contact solve here; it is refused naming ``case``. QUAD8's consistent nodal forces of a uniform pressure are negative at
the corners (∫N_corner = −|cell|/12, ∫N_mid = |cell|/3), but every registered cone is on the
multiplier's coefficients (nodal values, pointwise values, dual or discontinuous coefficients),
and the coefficients of the constant are λ·1 > 0 in each basis that holds it (nodal bases
interpolate; the dual bases, Popp-transformed or not, are partitions of unity); the weighted gaps
vanish since the traces coincide. So no cone is affected; what the negative corner weights change
is the PDAS's start: the unconstrained weighted gap −δ∫μ_j is positive at the corner nodes of the
standard QUAD8 basis (Q8, Q8-ALL), which start inactive and cost one more iteration (2, not 1).
The kernel: the first exploratory run (R5.2, 4:5) showed 4 modes that max(dim M − dim(W1 + W2), 0)
misses: QUAD8 traces have no cell centres, W_i = P2ˣ ⊗ P1ʸ + P1ˣ ⊗ P2ʸ on grid i, and a ⊗ b with
a, b ∈ P2(Ω2's grid) ⊥ P1 on both grids (dim 2 per direction on n:n+1) is orthogonal to both.
That count (:meth:`~infsup_contact.discretization.face.shapes.serendipity.SerendipitySquare.natural_modes`,
in the ledger's prediction, :mod:`.claims.membranes3d_studies`) was then computed for every space
before the table: 4 for R5.2 and DUAL-ALL, 1 for R5.4 on 4:5 and 7:8 (16, 16, 9 and DUAL's 4 on
matching 4:4), 0 for the rest. A kernel leaves u_h exact and λ_h to the PDAS's minimum-norm choice.

*Outcome* (N1:N2 = 4:5, 7:8 and 4:4, G_h = trace of Ω2; 36 rows, 2.5 s): as predicted. T4, T5,
DUAL, TDUAL-Q8, Q8-ALL, DISC-P1 (and CalculiX's LINMORTAR duals LINDUAL0-Q8, LINDUAL-Q8, registered
later: predicted PASS, count 0, then ≤ 1.3e-13 on the three pairs) reproduce λ to ≤ 5e-10 and u to ≤ 2e-14 of δ (DUAL at 4:4, with
its 4 modes, excepted: λ error 1.4); T3, Q8, LIN0-Q8 fail (λ error 1.0–1.7, u error 1–8e-2 δ).
The kernel rows keep u to ≤ 6e-13 but not λ: R5.2 (0.45), DUAL-ALL (2.4); R5.4's modes are
orthogonal to 1 (λ error 8e-13 on 4:4 with 9 modes) but ill-separated on 4:5 and 7:8 (7e-9, and 5e-8
with 3 measured modes: inconclusive in the ledger). Measured
kernels equal the count except R5.4 on 7:8 (3 ≥ 1: the count is a lower bound).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import ngsolve
import numpy as np

from ...discretization.gamma.constants import spans_constants
from ...discretization.spaces import registry
from ...discretization.segment.meshes import DIRICHLET
from ...errors import InputError
from ...models import make_model
from ...contact.contact import contact_pair, solve_contact_on
from ...solvers.request import MeshOptions
from ..contact.registry import FACE_PATCH
from . import table
from .table import KERNEL_RTOL

SCENE = FACE_PATCH.id
"""This scene's registry id (:mod:`..scene_registry` declares it and its models)."""
DELTA = 1e-2
"""Default downward displacement δ of Ω2's far face."""
PASS_RTOL = 1e-7
"""λ_h = λ and u_h = u to this relative accuracy count as passing (the ledger's ``PATCH_RTOL``,
:mod:`infsup_contact.study.claims.membranes3d_studies`: a decade above the round-off spread of the
least-conditioned row across BLAS code paths)."""


@dataclass(frozen=True)
class PressedCubes:
    """The face patch test's data (a contact scene of the 3D membranes, model contract).

    Attributes
    ----------
    name : str
        The scene's registry id.
    c1, c2 : float
        Material scales (prestress) of Ω1, Ω2.
    d : float
        Downward displacement δ of Ω2's far face.
    supports : str
        Where u_i is prescribed (NGSolve boundary regexp): the far faces only.
    """

    name: str
    c1: float
    c2: float
    d: float
    supports: str = DIRICHLET

    @property
    def far_displacement(self) -> tuple:
        """u_i on the far face of Ω1, Ω2."""
        return (0.0, -self.d)

    @property
    def pressure(self) -> float:
        """λ = δ / (1/c1 + 1/c2) (module docstring)."""
        return self.d / (1.0 / self.c1 + 1.0 / self.c2)

    def exact(self) -> tuple:
        """(u1, u2) as NGSolve coefficient functions of z (module docstring)."""
        lam = self.pressure
        return -lam / self.c1 * ngsolve.z, -self.d + lam / self.c2 * (2.0 - ngsolve.z)

    def exact_values(self, i: int, points: np.ndarray) -> np.ndarray:
        """u_{i+1} at ``points`` (n, 3): :meth:`exact` in numpy, what every body's u_h is compared with."""
        lam, z = self.pressure, np.asarray(points, float)[:, 2]
        return -lam / self.c1 * z if i == 0 else -self.d + lam / self.c2 * (2.0 - z)


def patch_scene(c=(1.0, 1.0), delta: float = DELTA) -> PressedCubes:
    """The scene's data with material scales ``c`` and far-face displacement ``delta``."""
    if not (np.isfinite(delta) and 0.0 < delta < 1.0):
        raise InputError("delta", "0 < delta < 1", got=delta)
    return PressedCubes(SCENE, float(c[0]), float(c[1]), float(delta))


def patch_pair(k: int, n1: int, n2: int, c=(1.0, 1.0), delta: float = DELTA, element: str = "hex", model=None):
    """Both factorized bodies of the scene (one per body, shared by every case)."""
    model = make_model(FACE_PATCH.models[0]) if model is None else model
    return contact_pair(patch_scene(c, delta), k, "structured", n1, n2, model, MeshOptions(element=element))


def solve_face_patch(case: str, k: int, n1: int, n2: int, c=(1.0, 1.0), delta: float = DELTA,
                     element: str = "hex", pair=None, per_cell: int = 4, multiplier_mesh: str = "omega2",
                     scene=None) -> dict:
    """Solve the face patch test for one case on G_h = ``multiplier_mesh`` (``omega2``: the trace
    of Ω2; ``union``: the common refinement, where dim M_h exceeds the traces' and K has a
    kernel); one row of measures.

    ``scene``: another uniform-pressure scene on the face, with this scene's ``name``, ``d``,
    ``pressure`` and ``exact()`` (one NGSolve coefficient function per body, scalar or vector
    as the model's u_h), solved on ``pair`` (built from it); default :func:`patch_scene` of
    ``pair.c`` and ``delta`` (the elastic one: :mod:`.elastic3d`).

    Returns
    -------
    dict
        ``lambda_max_rel_error`` = max |λ_h − λ|/λ at ``per_cell`` + 1 points per direction of
        every rectangle of the common refinement of G_h and both traces (∂Γ included);
        ``u_max_rel_error`` = max |u_h − u| / δ at the same number of points per direction of
        every cell of both bodies (:func:`body_points`);
        ``passes`` (both ≤ :data:`PASS_RTOL`); ``predicted`` (1 ∈ M_h, computed on the space
        the solve uses: :func:`~infsup_contact.discretization.gamma.constants.spans_constants`) and
        ``segment_rule`` (the registry's ``contains_constants(k)``, the segment's answer);
        ``kernel_dim`` of K against the L²(Γ) Gram matrix; PDAS ``nonunique``, iterations.
    """
    registry.check_case(case, k)
    t0 = time.perf_counter()
    if pair is None:
        pair = patch_pair(k, n1, n2, c, delta, element)
    scene = patch_scene(pair.c, delta) if scene is None else scene
    delta = scene.d
    sol = solve_contact_on(pair, case, multiplier_mesh, time_floor=False)
    space, gamma, res = sol.space, sol.gamma, sol.pdas
    lam = scene.pressure
    x = gamma.sample(gamma.common_refinement(space.breakpoints, *(s.trace.partition for s in sol.sides)), per_cell)
    lam_err = float(np.max(np.abs(sol.pressure(x) - lam)) / lam)
    u_err = max(float(np.max(np.abs(v - np.ravel(scene.exact_values(i, p)))))
                for i, gf in enumerate(sol.u) for p, v in [body_samples(gf, per_cell)]) / delta
    G, _ = gamma.gram(space, "L2")
    spec = registry.space_spec(case)
    return dict(scene=scene.name, case=case, k=k, family="structured", element=element, N1=n1, N2=n2,
                multiplier_mesh=multiplier_mesh,
                c1=pair.c[0], c2=pair.c[1], delta=delta, pressure=lam, dim_M=space.dim, cone=spec.cone(k),
                kernel_dim=table.kernel_dim(sol.K, G, KERNEL_RTOL), nonunique=bool(res.nonunique),
                iterations=res.iterations, n_active=int(res.active.sum()),
                lambda_max_rel_error=lam_err, u_max_rel_error=u_err,
                passes=bool(lam_err <= PASS_RTOL and u_err <= PASS_RTOL),
                predicted=spans_constants(space), segment_rule=spec.contains_constants(k),
                seconds=time.perf_counter() - t0)


def body_samples(f, per_cell: int) -> tuple:
    """(points (n, 3), u_h there, flattened) at ``per_cell`` + 1 points per direction of every cell of
    the body u_h lives on: an NGSolve GridFunction at :func:`body_points` of its mesh, a HEX20 field
    (:class:`~infsup_contact.models.hex20.Hex20Field`) at its own cells' points (``samples``)."""
    if hasattr(f, "samples"):
        return f.samples(per_cell)
    p = body_points(np.array([v.point for v in f.space.mesh.vertices]), per_cell)
    return p, body_values(f, p)


def body_points(vertices: np.ndarray, per_cell: int) -> np.ndarray:
    """The tensor grid (n, 3) of ``per_cell`` + 1 points per direction in every cell of the
    structured vertex lattice of ``vertices`` (nv, 3) (faces and edges included)."""
    t = np.linspace(0.0, 1.0, per_cell + 1)
    axes = []
    for d in range(3):
        g = np.unique(np.round(vertices[:, d], 12))
        axes.append(np.unique((g[:-1, None] + np.outer(np.diff(g), t)).ravel()))
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def body_values(f, points: np.ndarray, mesh=None) -> np.ndarray:
    """Values of a GridFunction (or a coefficient function on ``mesh``) at ``points`` (n, 3),
    flattened: point evaluation, not interpolation (NGSolve's ``Set`` of a linear function leaves
    its higher-order coefficients at ~1e-13, not 0)."""
    mesh = f.space.mesh if mesh is None else mesh
    return np.asarray(f(mesh(points[:, 0], points[:, 1], points[:, 2]))).ravel()


def face_patch_rows(cases, ks, pairs, c=(1.0, 1.0), delta: float = DELTA, element: str = "hex", model=None) -> list:
    """:func:`solve_face_patch` for every case defined for each k and every (N1, N2) pair
    (:func:`.table.patch_rows`)."""
    return table.patch_rows(lambda k, n1, n2: patch_pair(k, n1, n2, c, delta, element, model),
                            lambda case, k, n1, n2, pair: solve_face_patch(case, k, n1, n2, c, delta, element,
                                                                           pair=pair),
                            cases, ks, pairs)


def face_patch_table(cases, ks, pairs, elements, model: str | None = None) -> list:
    """The DAG's patch table (rule face_patch, config ``face.patch``): :func:`face_patch_rows`
    for every element of ``model`` (default the scene's first), restricted to the ``cases``
    that element's face builds (``Interface.builds``: the QUAD9-element spaces pair with
    rectangles only, the QUAD8 ones with HEX20 bodies) and to the ``ks`` its bodies have
    (``Interface.allows``: HEX20 k = 2 only; the config check refuses an element with none of
    them), every non-matching pair. A Petrov–Galerkin pair (two bases: a β_h question only, the
    contact solve has one) is left out, as ``contact --case all`` leaves it out."""
    from ..claims.membranes3d import element_interfaces

    name = FACE_PATCH.models[0] if model is None else model
    gammas = element_interfaces(name, elements)
    rows = []
    for element in elements:
        own = [c for c in cases if gammas[element].builds(registry.space_spec(c))
               and not registry.space_spec(c).petrov_galerkin]
        own_ks = [k for k in ks if gammas[element].allows(int(k))]
        rows += face_patch_rows(own, own_ks, pairs, element=element, model=make_model(name))
    return rows
