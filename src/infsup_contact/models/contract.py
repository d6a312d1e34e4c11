"""The model seam: what a physical model must give the Γ-reduced engine.

β_h (:mod:`infsup_contact.solvers.infsup`), the contact solver
(:mod:`infsup_contact.contact.contact`), the ledger and the paper take a :class:`Model` and
never ask which one it is. A model is one function, ``side_operator(mesh, k)``, applied to
each mesh of a pair; the :class:`~infsup_contact.models.contract.SideOperator` it returns carries

* ``trace`` — the Γ trace of the side's displacement space: its interface (``trace.gamma``,
  the :class:`~infsup_contact.discretization.gamma.interface.Interface` every consumer asks for
  partitions, quadrature, Gram matrices and spaces), its partition of Γ (``trace.partition``,
  opaque outside the interface), its Γ dofs (``trace.gamma_dofs``, the components b(v, μ) sees:
  for a scalar membrane v itself, for an elastic body v·n) and the NGSolve space, from which
  :func:`~infsup_contact.discretization.gamma.coupling.coupling_matrix` builds B_i;
* ``steklov_times(M)`` — X_i M with X_i = (A_i⁻¹)_ΓΓ at unit material scale: the interface
  operator Σ_i B_i X_i B_iᵀ / c_i is assembled from it for every multiplier space and norm
  (above ``interface_operator.SPARSE_PRODUCT_MIN_DIM`` from ``steklov_sandwich(B)`` = B X_i Bᵀ where the side
  has it: :class:`~infsup_contact.models.contract.SideOperator` forms X_i once);
* ``solve``, ``free``, ``stiffness`` — the factorization and the free dofs (Γ last) with
  which the contact solver recovers u_h = A_i⁻¹ (F_i ∓ B_iᵀ λ_h).

Contact asks a model four more things, so that one Γ solve
(:func:`~infsup_contact.contact.contact.solve_on_gamma`) serves every model and scene:

* ``scene_side(scene, mesh, k)`` — the side of a contact scene (a scene may put its own
  supports on ∂Ω_i∖Γ, such as the elastic patch test's rollers);
* ``load(side, scene, i)`` — F_i on the free dofs of side i (i = 0 for Ω1, 1 for Ω2) and the
  Dirichlet lift u_{D,i} on all dofs (None: homogeneous), read off the scene's data;
* ``field(side, values, lift)`` — u_h as an NGSolve GridFunction from its free-dof values;
* ``interpolate(side, components)`` — the interpolant of a field given by NGSolve
  coefficient functions (one per component), all dofs: what a scene with an exact u compares.

**Normal and sign.** Every model uses b(v, μ) = ∫_Γ (v_2·n − v_1·n) μ with n = e_y (from Ω1
into Ω2; e_z for the 3D bodies on the face Γ = (0,1)²×{1}), so A_1 u_1 = F_1 − B_1ᵀ λ and A_2 u_2 = F_2 + B_2ᵀ λ (:data:`B_SIGN`), and λ ≥ 0
pushes the bodies apart: λ = −c_i ∂u_i/∂x_2 for the membranes, λ = −σ_yy for elastic bodies.
The outward normal of side i on Γ is ``OUTWARD_NORMAL_Y[i]`` e_y.

The material enters only as the scale c_i of each side (A_i = c_i K_i), so one side
operator per (mesh, k) serves every material pair; data that changes K_i itself (an
elastic body's ν) belongs to the model instance.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.gamma.trace import GammaTrace
from ..la import body_parity, schur
from ..la.schur import SteklovProduct
from ..la.threaded import concurrent_map
from . import body_symmetry


@dataclass(frozen=True)
class Body:
    """A body's mesh and its Γ, as a 3D model's mesh builder returns them (``Model.mesh``): which
    interface the face is (rectangles, structured triangles, a general triangulation) is the
    builder's to say, from the request (family, element), and is never attached to the mesh.

    Attributes
    ----------
    mesh : ngsolve.Mesh
        The mesh of Ω_side, its Γ named as ``interface`` expects.
    interface : Interface
        Γ (:class:`~infsup_contact.discretization.gamma.interface.Interface`) whose trace the side takes.
    """

    mesh: object
    interface: object


@dataclass(frozen=True)
class OptionalChoice:
    """The allowed values of a mesh option a request may leave unset (then the builder's default
    applies and the table has no column for it), unlike a tuple of choices, whose first is filled in.

    Attributes
    ----------
    values : tuple of str
        The allowed strings (empty for a number).
    text : str
        The allowed values in words (a number's range).
    above : float or None
        A number option: the values are the numbers > ``above`` (inf included, nan not).
    filled_when : tuple
        (option, value): the first of ``values`` is filled in when that other option has that value
        (the arc's ``coupling`` once ``gamma`` is ``arc``); () never.
    """

    values: tuple = ()
    text: str = ""
    above: float | None = None
    filled_when: tuple = ()

    def __contains__(self, value) -> bool:
        if self.above is None:
            return value in self.values
        return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
            and value > self.above

    def __iter__(self):
        return iter(self.values)

    def __str__(self) -> str:
        return self.text or ", ".join(self.values)

    def parse(self, text: str):
        """The command line's value: a float for a number option (``inf`` too), else the string."""
        if self.above is None:
            return text
        try:
            return float(text)
        except ValueError:
            return text  # refused with the allowed range by the request's check


@dataclass(frozen=True)
class MaterialParam:
    """One material parameter of a model, as the command line and the tables see it.

    Attributes
    ----------
    name : str
        The flag (``--name``) and the table column.
    default : float
        Its value when not given.
    check : callable
        ``check(value, name) -> float``: the value, or an ``InputError`` naming ``name`` and
        the allowed range.
    allowed : str
        The allowed range in words (for ``--help``).
    help : str
        What it is, one phrase.
    side : int or None
        0 or 1: the material scale c_1 or c_2 of that side (A_i = c_i K_i); None: a parameter
        of K_i itself, passed to ``models.make_model``.
    """

    name: str
    default: float
    check: Callable
    allowed: str
    help: str
    side: int | None = None


@dataclass(frozen=True)
class Model:
    """A physical model as the engine sees it.

    Attributes
    ----------
    name : str
        Identifier used on the command line and in tables.
    side_operator : callable
        ``side_operator(mesh, k) -> SideOperator``: one body, factorized once, Γ dofs last,
        unit material scale.
    description : str
        One line for ``--help`` and the paper.
    scene_side, load, field, interpolate : callable, optional
        What contact needs (module docstring); a model without them serves β_h only.
    params : tuple of MaterialParam
        The material parameters the model takes (the command line's material flags, in this
        order): the scales c_1, c_2 of the two sides under the model's names, and parameters
        that change K_i itself (built into the model by ``models.make_model``).
    components : int
        Displacement components per node (the memory estimate's factor).
    mesh : callable or None
        ``mesh(family, n, side, **mesh_kwargs) -> Body``: the mesh of Ω_side with n cells on Γ
        (per direction on a face) and its Γ, what ``side_operator`` takes; None: the paper's 2D meshes
        (:func:`~infsup_contact.discretization.segment.meshes.subdomain_mesh`).
    mesh_options : tuple of (str, tuple or OptionalChoice)
        Mesh keywords the model's ``mesh`` takes beyond the 2D ones, with their allowed values
        (``(("element", ("hex", "tet")),)``, the first the default; an :class:`OptionalChoice` for
        an option left unset unless given; a tuple, so that a model stays hashable, a side
        cache key): what the command line offers for this model only.
    families : tuple of str or None
        Mesh families the model's ``mesh`` builds (None: every 2D family).
    interface : callable or None
        ``interface(family, **mesh_kwargs) -> Interface``: the Γ of the model's bodies for the
        request's options (its element's face, curved by ``gamma``/``radius``/``coupling``), checked
        and resolved without a mesh (:mod:`~infsup_contact.discretization.spaces.gammas`); None:
        the 2D membranes' Γ, the paper's segment or the arc (:meth:`gamma`).
    curving : tuple of str
        The Γ table's (flat, curved) shape names its ``gamma`` option chooses between
        (``("segment", "arc")``); () for a model without the option.
    dim : int
        Space dimension of the bodies (2, or 3 with a contact face): the memory estimate's model.
    mirror_side : callable or None
        ``mirror_side(side1, mesh2, k) -> SideOperator``: Ω2's side of a matching pair, reusing
        Ω1's factorization where a mirror maps the bodies (checked; else built as
        ``side_operator``); None: every side is factorized.
    matching_pair : callable or None
        ``matching_pair(mesh1, make_mesh2, k) -> (side1, side2)``: the sides
        ``side_operator(mesh1, k)`` and ``mirror_side(side1, make_mesh2(), k)`` give, with side 1's
        factorization beside the build of side 2; None: one after the other.
    """

    name: str
    side_operator: Callable
    description: str = ""
    scene_side: Callable | None = None
    load: Callable | None = None
    field: Callable | None = None
    interpolate: Callable | None = None
    params: tuple = ()
    components: int = 1
    mesh: Callable | None = None
    mesh_options: tuple = ()
    families: tuple | None = None
    dim: int = 2
    mirror_side: Callable | None = None
    matching_pair: Callable | None = None
    interface: Callable | None = None
    curving: tuple = ()

    def subdomain_mesh(self, family: str, n: int, side: int, *, checked: bool = False, gamma=None,
                       **mesh_kwargs):
        """The mesh of Ω_side the model's sides are built on (its ``mesh`` builder, else the 2D one),
        from the builder's own options ``mesh_kwargs``, on the request's Γ ``gamma`` (its own
        argument: an Interface resolved by :meth:`gamma`; None: the flat one).
        ``checked``: the arguments are a validated request's, not checked again by the 2D builder
        (a model's own builder keeps its checks)."""
        if self.mesh is None:
            from ..discretization.segment import meshes

            mesh = meshes.subdomain_mesh(family, n, side, checked=checked, **mesh_kwargs)
            flat = gamma is None or gamma == self.gamma(family)
            return mesh if flat else Body(mesh, gamma)  # the square's mesh, curved with the side
        return self.mesh(family, n, side, **mesh_kwargs, **({} if gamma is None else {"gamma": gamma}))

    def gamma(self, family: str = "structured", **mesh_kwargs):
        """The Γ of the model's meshes with these options (an element's face; the paper's segment or
        the arc for the 2D meshes): a property of the request, not of N, resolved without a mesh
        (``interface``; the checks of the Γ table, :mod:`~infsup_contact.discretization.spaces.gammas`).
        An Interface given as ``gamma`` is the request's, resolved before."""
        given = mesh_kwargs.get("gamma")
        if given is not None and not isinstance(given, str):
            return given
        if self.interface is not None:
            return self.interface(family, **mesh_kwargs)
        if self.mesh is not None:  # a model that declares no interface: asked of its coarsest body
            return self.mesh(family, 1, 1, **mesh_kwargs).interface
        from ..discretization.spaces.gammas import curved_of, gamma_of

        curving = self.curving or (PAPER_GAMMA, "arc")
        return curved_of(gamma_of(curving[0]), curving, *(mesh_kwargs.get(key) for key in ("gamma", "radius", "coupling")))

    def gamma_columns(self, gamma) -> dict:
        """The table columns of a request's Γ (``gamma`` an Interface, or None where the request
        names none): the curved shape's name, radius and coupling; the flat one's name."""
        if gamma is None or not self.curving:
            return {}
        if not hasattr(gamma, "radius"):
            return {"gamma": self.curving[0]}
        return {"gamma": self.curving[1], "radius": gamma.radius, "coupling": gamma.coupling}

    def param_names(self) -> list:
        """The names of the model's material parameters (its flags without ``--``)."""
        return [p.name for p in self.params]

    def side_for(self, scene, mesh, k: int):
        """The side of ``scene`` on ``mesh``: ``scene_side`` where the model has one, else the
        β_h side (a scene that changes nothing of ∂Ω_i∖Γ)."""
        if self.scene_side is None:
            return self.side_operator(mesh, k)
        return self.scene_side(scene, mesh, k)


PAPER_GAMMA = "segment"
"""The Γ table's shape (:mod:`~infsup_contact.discretization.spaces.gammas`) of the paper's 2D
meshes: the Γ of a bare mesh (one given without its :class:`Body`), and the flat Γ of a 2D model
that names no ``curving``."""

B_SIGN = (-1.0, 1.0)
"""Sign of B_iᵀ λ in A_i u_i = F_i + sign_i B_iᵀ λ (Ω1, Ω2): b(v, μ) = ∫_Γ (v_2 − v_1)·n μ."""
OUTWARD_NORMAL_Y = (1.0, -1.0)
"""y component of the outward normal of Ω1, Ω2 on Γ (Ω1 lies below Γ)."""


@dataclass(frozen=True)
class SideOperator(SteklovProduct):
    """Factorized stiffness of one body and its Γ Schur complement (unit material scale).

    Attributes
    ----------
    trace : GammaTrace
        Γ dofs and trace elements of V_{h,i}.
    free : ndarray of int
        Free NGSolve dofs (the unknowns of A_i), Γ dofs included.
    stiffness : scipy.sparse.csc_matrix
        K_i restricted to free dofs, in the order of ``free``.
    schur : ndarray
        S_i = Schur complement of K_i onto the Γ dofs (order of ``trace.gamma_dofs``).
    solve : callable
        b ↦ K_i⁻¹ b on free dofs (reuses the factorization).
    """

    trace: GammaTrace
    free: np.ndarray
    stiffness: sp.csc_matrix
    schur: np.ndarray
    solve: object
    steklov: np.ndarray | None = None
    signature: np.ndarray | None = None
    """Per free dof, what a symmetry maps as it maps points (:mod:`.body_symmetry`; None: not known)."""
    route: str = ""
    """How it was factorized: ``"parity 4"`` / ``"parity 2"`` (the body's symmetry parts),
    ``"mirror"`` (side 1's, permuted), else the :func:`~.schur.gamma_factorization` route."""
    steklov_parts: tuple | None = None
    """X = ``steklov`` in the body's parity blocks, ((P_c, X_c), ...) with X = Σ_c P_c X_c P_cᵀ
    (P_c sparse, n_Γ × n_c, orthonormal columns): a side factorized in parity parts (or mirrored
    from one); None otherwise. The sandwiches B X Bᵀ of a split space take them
    (:mod:`~infsup_contact.la.parity_sandwich`)."""

    @property
    def ndof(self) -> int:
        return len(self.free)

    def steklov_inverse(self, c: float = 1.0) -> np.ndarray:
        """X_i = (A_i⁻¹)_ΓΓ = S_i⁻¹ / c_i, symmetric positive definite."""
        X = self.steklov if self.steklov is not None else sla.inv(self.schur, check_finite=False)
        return X / c

    def forget_cached(self) -> None:
        """Return to the state right after the build: drop what later calls cached on this
        side (the Cholesky factor of S, the trace's basis values, dense and CSR). A benchmark
        times each multiplier space's solve from this state, as a fresh build would give it."""
        self.__dict__.pop("_schur_cholesky", None)
        self.__dict__.pop("_steklov_explicit", None)
        self.trace.forget_basis()



def factorized_side(trace: GammaTrace, free: np.ndarray, K, route: str = "auto",
                    keep_factor: bool = False, signature: np.ndarray | None = None,
                    parts_map=concurrent_map) -> SideOperator:
    """The SideOperator of an assembled stiffness K (free dofs, Γ last): one
    :func:`gamma_factorization` (``keep_factor`` for a side that will solve: a contact scene's).

    With a ``signature`` of the free dofs (:mod:`.body_symmetry`) a body invariant under the
    square's reflections (checked on K, Γ to Γ) is factorized in its parity parts instead
    (:mod:`~infsup_contact.la.body_parity`: the same S and solves to round-off, a fraction of
    the flops); any other body, or no signature, takes the general route. ``parts_map`` runs the
    parts' factorizations, independent calls (default :func:`~infsup_contact.la.threaded.concurrent_map`:
    side by side on the request's threads, one BLAS thread each, in turn inside another task; the
    built-in ``map``: one by one). A side that will solve (``keep_factor``: a contact scene's)
    keeps the general route: its solves agree with the parity route's to round-off only, and the
    ledger's patch tests print round-off quantities (R5.4's λ error on tetrahedra sits within 2× of
    its 1e-8 threshold), which must not move with the route of a β_h speed-up."""
    n_gamma = len(trace.gamma_dofs)
    bases = None if keep_factor else body_symmetry.parity_bases(signature, K, n_gamma)
    if bases is not None:
        parts = body_parity.parity_parts(K, n_gamma, bases)
        S, solve, X, blocks = parts.factorize(
            lambda Kc, ng: schur.gamma_factorization(Kc, ng, route, gamma_dim=trace.gamma.dim,
                                                     keep_factor=keep_factor), parts_map)
        return SideOperator(trace, free, K, S, solve, X, signature, f"parity {len(parts.parts)}", blocks)
    fac = schur.gamma_factorization(K, n_gamma, route, gamma_dim=trace.gamma.dim, keep_factor=keep_factor)
    return SideOperator(trace, free, K, fac.schur, fac.solve, fac.steklov, signature, fac.route)


def extended(base: SideOperator, cls, **extra):
    """``base`` as the subclass ``cls`` of :class:`SideOperator` with its ``extra`` fields."""
    return cls(**{f.name: getattr(base, f.name) for f in fields(SideOperator)}, **extra)


def mirrored_side(side1: SideOperator, trace: GammaTrace, free: np.ndarray, K, signature, route: str = "auto",
                  keep_factor: bool = False, sigma=body_symmetry.SEARCH) -> SideOperator:
    """Body 2 of a matching pair from body 1's factorization: where a mirror maps body 2 onto
    body 1 and K is side 1's stiffness permuted, entry by entry
    (:func:`~.body_symmetry.mirrored_factors`; ``sigma``: its permutation, already looked for),
    S and the solves are side 1's permuted; else :func:`factorized_side`."""
    factors = body_symmetry.mirrored_factors(side1, signature, K, sigma)
    if factors is None:
        return factorized_side(trace, free, K, route, keep_factor, signature)
    S, solve, X, blocks = factors
    return SideOperator(trace, free, K, S, solve, X, signature, "mirror", blocks)


def schur_by_solves(side: SideOperator) -> np.ndarray:
    """Reference route: S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ by a multi-right-hand-side solve."""
    ng = len(side.trace.gamma_dofs)
    K = side.stiffness
    KII, KIG, KGG = K[:-ng, :-ng].tocsc(), K[:-ng, -ng:].toarray(), K[-ng:, -ng:].toarray()
    return KGG - KIG.T @ spla.splu(KII).solve(KIG)
