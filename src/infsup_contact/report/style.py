"""Shared figure style: one colour and one marker per case, the same in every figure.

Colours are the Okabe–Ito palette (distinguishable under the common colour-vision
deficiencies); every case also has its own marker, and stable cases (Thm 3, 4, 5) are
drawn solid, unstable ones (Rem 5.2, 5.4) dashed, so no figure relies on colour alone.
Displacement degree k is the marker fill (k = 1 open, k = 2 filled, k = 3 left half,
k = 4 top half) wherever two degrees share an axes.

Every figure script draws from tables only and saves through :func:`save_figure`
(PDF and PNG, atomically, with deterministic metadata).
"""
from __future__ import annotations

import logging
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from collections.abc import Mapping
from types import MappingProxyType

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..discretization.spaces.registry import SPACES, space_spec  # noqa: E402
from .case_styles import CASE_STYLES, NEUTRAL, OKABE_ITO, WIDE_MARKERS  # noqa: E402


def _color(spec) -> str:
    return OKABE_ITO[CASE_STYLES[spec.id][0]] if spec.id in CASE_STYLES else NEUTRAL


def _marker(spec) -> str:
    return CASE_STYLES[spec.id][1] if spec.id in CASE_STYLES else "8"


class _RegistryView(Mapping):
    """case id → one attribute of its registry entry; live, so spaces registered later
    (dual, user spaces) are drawn like the paper's."""

    def __init__(self, get):
        self._get = get

    def __getitem__(self, case):
        if case not in SPACES:
            raise KeyError(case)
        return self._get(SPACES[case])

    def __iter__(self):
        return iter(SPACES)

    def __len__(self):
        return len(SPACES)


#: case → colour; THE map every figure uses (read-only, from the registry).
CASE_COLORS = _RegistryView(_color)
#: case → marker.
CASE_MARKERS = _RegistryView(_marker)
#: paper reference of each case (legend text).
CASE_REFS = _RegistryView(lambda s: s.paper_ref)
#: displacement degree → marker fill style.
K_FILL = MappingProxyType({1: "none", 2: "full", 3: "left", 4: "top"})
#: axis labels used by every figure.
LABELS = MappingProxyType({
    "h": r"mesh size $h = 1/N_2$",
    "beta_H": r"$\beta_h$  ($\mu$ in $H^{-1/2}_{00}(\Gamma)'$ norm)",
    "beta_L2": r"$\beta_h$  ($\mu$ in $L^2(\Gamma)$ norm)",
    "x": r"$x_1$ along $\Gamma$",
    "seconds": "wall time [s]",
})
#: error measure (contact.csv column) → (short title, axis label).
MEASURES = MappingProxyType({
    "energy_error": ("energy", r"$\|u-u_h\|_a$"),
    "l2_error": (r"$L^2(\Omega)$", r"$\|u-u_h\|_{L^2(\Omega)}$"),
    "lambda_l2_error": (r"$\lambda$ in $L^2(\Gamma)$", r"$\|\lambda-\lambda_h\|_{L^2(\Gamma)}$"),
    "lambda_hm12_error": (r"$\lambda$ in $H^{-1/2}(\Gamma)$", r"$\|\lambda-\lambda_h\|_{H^{-1/2}_{00}(\Gamma)'}$"),
})

RC = {
    "font.size": 9,
    "axes.titlesize": 9.5,
    "axes.labelsize": 9,
    "legend.fontsize": 7.5,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "lines.linewidth": 1.4,
    "lines.markersize": 5,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "legend.framealpha": 0.85,
    "savefig.dpi": 200,
    "pdf.fonttype": 42,
    "svg.hashsalt": "infsup-contact",
}


@contextmanager
def style():
    """The project's rcParams for the duration of one figure."""
    with plt.rc_context(RC):
        yield


def is_stable(case: str) -> bool:
    """Whether the case is expected stable (the paper's Thm 3, 4, 5; the registry's entry)."""
    return space_spec(case).stable


def case_style(case: str, k: int | None = None, **overrides) -> dict:
    """Keyword arguments for ``Axes.plot`` of one (case, k) series."""
    color = CASE_COLORS[case]
    kw = dict(color=color, marker=CASE_MARKERS[case], markeredgecolor=color,
              linestyle="-" if is_stable(case) else "--")
    if k is not None:
        kw["fillstyle"] = K_FILL.get(int(k), "full")
        kw["markerfacecoloralt"] = "white"
    kw.update(overrides)
    return kw


def case_label(case: str, k: int | None = None) -> str:
    """Legend text: ``T3 (Thm 3)`` or ``T3 (Thm 3), k=2``."""
    return space_spec(case).label(k)


def ordered_cases(cases) -> list:
    """Cases in registry order (the paper's T3 R5.2 T4 R5.4 T5 first; unknown ids last, sorted)."""
    cases = set(cases)
    return [c for c in SPACES if c in cases] + sorted(c for c in cases if c not in SPACES)


def mesh_size(frame):
    """h = 1/N2 of each row (N2 or N column)."""
    col = "N2" if "N2" in frame.columns else "N"
    return 1.0 / frame[col].astype(float)


def slope_triangle(ax, x0: float, y0: float, slope: float, decades: float = 0.4,
                   label: str | None = None, below: bool = True, color: str = NEUTRAL):
    """A log–log reference triangle of the given slope with its corner at (x0, y0).

    The hypotenuse runs from (x0, y0) to (x0·10^decades, y0·10^(slope·decades)); the legs
    are horizontal and vertical, below the hypotenuse (``below=True``) or above it.
    """
    x1 = x0 * 10**decades
    y1 = y0 * 10 ** (slope * decades)
    corner = (x1, y0) if below else (x0, y1)
    ax.plot([x0, x1, corner[0], x0], [y0, y1, corner[1], y0], color=color, lw=0.9, zorder=1)
    text = label if label is not None else f"{slope:g}"
    if below:
        ax.text(x1 * 1.04, np.sqrt(y0 * y1), text, color=color, ha="left", va="center", fontsize=8)
    else:
        ax.text(np.sqrt(x0 * x1), y1 * 1.06, text, color=color, ha="center", va="bottom", fontsize=8)


def save_figure(fig, pdf, png) -> None:
    """Write ``fig`` as PDF and PNG atomically (temporary file + rename), then close it.

    Metadata that changes run to run (creation date) is dropped, so reruns give
    identical files.
    """
    # fontTools (TrueType subsetting for pdf.fonttype 42) warns about the font's old timestamp
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    try:
        for path, fmt, meta in ((pdf, "pdf", {"CreationDate": None, "Creator": None, "Producer": None}),
                                (png, "png", {"Software": None})):
            path = Path(path)
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=f".{fmt}")
            os.close(fd)
            try:
                fig.savefig(tmp, format=fmt, metadata=meta, bbox_inches="tight", pad_inches=0.03)
                os.chmod(tmp, 0o644)
                os.replace(tmp, path)
            except BaseException:
                Path(tmp).unlink(missing_ok=True)
                raise
    finally:
        plt.close(fig)


__all__ = ["OKABE_ITO", "CASE_COLORS", "CASE_MARKERS", "CASE_REFS", "K_FILL", "NEUTRAL", "LABELS",
           "MEASURES", "RC", "style", "is_stable", "case_style", "case_label", "ordered_cases",
           "mesh_size", "slope_triangle", "save_figure"]


def h_ticks(axes, h, powers_of_two: bool = True) -> None:
    """Mesh-size ticks 1/N on log axes: at the powers-of-two N of the data (all N if fewer
    than two are powers of two, or if ``powers_of_two`` is False)."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    ns = sorted({int(round(1 / v)) for v in h})
    pow2 = [n for n in ns if n & (n - 1) == 0]
    ticks = pow2 if powers_of_two and len(pow2) >= 2 else ns
    for ax in np.ravel(axes):
        ax.xaxis.set_major_locator(FixedLocator([1 / n for n in ticks]))
        ax.xaxis.set_major_formatter(plt.FixedFormatter([f"1/{n}" for n in ticks]))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.xaxis.set_minor_formatter(NullFormatter())
