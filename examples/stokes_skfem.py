"""Stokes saddle-point systems assembled by scikit-fem: a producer this suite did not write.

Velocity in H¹₀((0,1)²)² with the H¹ seminorm (A = vector Laplacian, Dirichlet dofs removed
by scikit-fem's own ``get_dofs``/``complement_dofs``), pressure in L² (G = the pressure mass),
B = −div. The constant pressure is in the kernel of Bᵀ on every pair (an enclosed flow:
∫ div v = 0); the manifest declares it (``known_kernel: 1``), as a user of an enclosed
Stokes flow would.
"""
from __future__ import annotations

import numpy as np

PAIRS = {
    # pair: (velocity element, pressure element, mesh kind, textbook verdict (Boffi–Brezzi–Fortin))
    "P2-P1": ("ElementTriP2", "ElementTriP1", "tri", "stable"),     # Taylor–Hood
    "MINI": ("ElementTriMini", "ElementTriP1", "tri", "stable"),    # P1+bubble / P1
    "P2-P0": ("ElementTriP2", "ElementTriP0", "tri", "stable"),
    "P1-P1": ("ElementTriP1", "ElementTriP1", "tri", "unstable"),
    "Q1-P0": ("ElementQuad1", "ElementQuad0", "quad", "unstable"),  # checkerboard
}


def stokes_system(pair: str, n: int):
    """(A, B, G) of ``pair`` on the structured n × n mesh of the unit square."""
    import skfem
    from skfem.helpers import div, dot, grad, ddot

    ev, ep, kind, _ = PAIRS[pair]
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = (skfem.MeshTri if kind == "tri" else skfem.MeshQuad).init_tensor(x, x)
    ub = skfem.Basis(mesh, skfem.ElementVector(getattr(skfem, ev)()), intorder=4)
    pb = skfem.Basis(mesh, getattr(skfem, ep)(), intorder=4)

    @skfem.BilinearForm
    def laplace(u, v, w):
        return ddot(grad(u), grad(v))

    @skfem.BilinearForm
    def divergence(u, q, w):
        return -div(u) * q

    @skfem.BilinearForm
    def mass(p, q, w):
        return p * q

    A = laplace.assemble(ub)
    B = divergence.assemble(ub, pb)
    G = mass.assemble(pb)
    interior = ub.complement_dofs(ub.get_dofs())
    return A[interior][:, interior].tocsr(), B[:, interior].tocsr(), G.tocsr()


def time_one_level(pair: str, n: int) -> dict:
    """β_h of one level end to end (``level_spectrum``: kernel, factorizations, eigensolve,
    residuals) next to its reference cost measured in the same process: one sparse LU of A
    plus the eigensolve alone (the shift-invert Lanczos iterations on the already factorized
    operator, as ``level_spectrum`` reports them)."""
    import time

    import scipy.sparse.linalg as spla

    from infsup_contact.systems.engine import level_spectrum

    t0 = time.perf_counter()
    A, B, G = stokes_system(pair, n)
    t_assemble = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = level_spectrum(A, B, G, known_kernel=1)
    t_beta = time.perf_counter() - t0
    t0 = time.perf_counter()
    spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    t_lu = time.perf_counter() - t0
    reference = t_lu + res.seconds["eigen"]
    return dict(pair=pair, N=n, n=A.shape[0], m=B.shape[0], route=res.route, beta=res.beta,
                kernel_dim=res.kernel.dim, margin=res.kernel.margin_decades, residual=res.residual,
                t_assemble=t_assemble, t_beta=t_beta, t_lu_A=t_lu, t_eigen=res.seconds["eigen"],
                ratio=t_beta / reference, **{f"t_{k}": v for k, v in res.seconds.items() if k != "eigen"})


def main(argv=None) -> int:
    """``python examples/stokes_skfem.py write P2-P1 16 32 64 128 --out DIR [--format mtx]``
    writes the levels and a manifest (then: ``infsup-contact verdict --system DIR/levels.yaml``);
    ``python examples/stokes_skfem.py time P2-P1 128`` prints the timing row of one level."""
    import argparse
    import sys

    from infsup_contact.systems.export import write_system

    p = argparse.ArgumentParser(prog="stokes_skfem.py", description=main.__doc__)
    p.add_argument("what", choices=["write", "time"])
    p.add_argument("pair", choices=sorted(PAIRS))
    p.add_argument("N", type=int, nargs="+")
    p.add_argument("--out", default="stokes-levels")
    p.add_argument("--format", default="mtx", choices=["mtx", "npz", "petsc"])
    args = p.parse_args(argv)
    if args.what == "time":
        for n in args.N:
            print(time_one_level(args.pair, n), flush=True)
        return 0
    levels = [(1.0 / n,) + stokes_system(args.pair, n) for n in sorted(args.N)]
    print(write_system(args.out, levels, args.format, f"{args.pair} (scikit-fem)", known_kernel=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
