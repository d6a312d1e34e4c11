"""Measure the perturbed family's worst triangle against α (the bound of meshes.ALPHA_MAX).

For each α: over seeds 0..S−1, N = 4..32 and both sides, the smallest signed area of a
triangle relative to the unperturbed one (h²/2) and the smallest angle, next to the
guaranteed bounds of :func:`infsup_contact.discretization.segment.meshes.perturbation_bounds`
(every seed). Vertex arithmetic only (numpy): no NGSolve mesh is built.

    python workflow/scripts/alpha_bound.py [--seeds 200] [--csv out.csv]
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

from infsup_contact.discretization.segment.meshes import perturb, perturbation_bounds, signed_areas, structured_arrays

ALPHAS = (0.1, 0.15, 0.2, 0.22, 0.25, 0.3, 0.35, 0.4, 0.45)


def min_angles(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Smallest interior angle (degrees) of each triangle."""
    p = points[triangles]
    out = np.full(len(p), np.inf)
    for v in range(3):
        a, b = p[:, (v + 1) % 3] - p[:, v], p[:, (v + 2) % 3] - p[:, v]
        cos = np.einsum("nd,nd->n", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        out = np.minimum(out, np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return out


def measure(alpha: float, seeds: int, ns=range(4, 33)) -> dict:
    ratio, angle = np.inf, np.inf
    for n in ns:
        for side in (1, 2):
            points, triangles = structured_arrays(n, side)
            for seed in range(seeds):
                p = perturb(points, n, side, alpha, seed)
                areas = signed_areas(p, triangles) / (0.5 / n**2)
                ratio = min(ratio, float(areas.min()))
                ok = areas > 0  # an inverted triangle has no meaningful angle
                if ok.any():
                    angle = min(angle, float(min_angles(p, triangles[ok]).min()))
    bound_ratio, bound_angle = perturbation_bounds(alpha)
    return dict(alpha=alpha, min_area_ratio=ratio, min_angle_deg=angle,
                bound_area_ratio=bound_ratio, bound_angle_deg=bound_angle)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--csv")
    args = ap.parse_args()
    table = pd.DataFrame([measure(a, args.seeds) for a in ALPHAS])
    print(table.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    if args.csv:
        table.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
