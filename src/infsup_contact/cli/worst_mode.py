"""``beta --worst-mode FILE``: the worst mode of every β row drawn on Γ, one CSV.

For each (case, multiplier mesh, c pair, norm) row the eigenvector m of the smallest eigenvalue of
S m = β² G m (a kernel vector where β_h = 0; :mod:`infsup_contact.solvers.modes`), evaluated at
sample points of Γ as μ_h = Σ_j m_j μ_j(x) and normalized (max |μ_h| = 1, the peak positive).
Columns: case, multiplier_mesh, c1, c2, norm, beta, x (, y on a face), mu. A foreign system
(``--system``) has one mode per level, evaluated with the basis its manifest describes
(``levels[i].multipliers`` and ``gamma``), in Γ's own coordinates.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from .common import space_file

DESCRIPTION_NEEDED = ("a manifest whose levels describe their multipliers on Γ (the top key gamma and "
                      "levels[i].multipliers: `infsup-contact export --norm H` writes them)")
"""What ``--worst-mode`` with ``--system`` needs: the basis the mode is evaluated with."""


def check_worst_mode(args) -> None:
    """:class:`InputError` (key ``worst_mode``) when FILE is one of the request's inputs, or when
    a foreign system's manifest does not describe its multipliers (nothing to evaluate a mode with).
    The path itself (a directory, an unwritable place) is refused by its argparse type."""
    target = Path(args.worst_mode).resolve()
    inputs = []
    if args.system is not None:
        levels = args.manifest.levels
        inputs = [Path(args.system)] + [p for lv in levels for p in (lv.A, lv.B, lv.G, lv.constrained)
                                        if isinstance(p, Path)]
        bare = [lv.index for lv in levels if lv.multipliers is None]
        if bare:
            raise InputError("worst_mode", DESCRIPTION_NEEDED, got=f"{args.system} (levels[{bare[0]}] has no "
                             "multipliers)")
    if space_file(args) is not None:
        inputs.append(space_file(args))
    if any(p.resolve() == target for p in inputs):
        raise InputError("worst_mode", "a file other than the inputs of the request (it would be overwritten)",
                         got=str(args.worst_mode))


def mode_frame(modes, model_name: str | None = None):
    """The CSV table of :class:`~infsup_contact.solvers.modes.Mode` s: one row per sample point."""
    import numpy as np
    import pandas as pd

    from ..solvers.modes import mode_on_gamma

    parts = []
    for m in modes:
        x, mu = mode_on_gamma(m)
        head = dict(m.keys, beta=m.beta)
        cols = {"x": x} if np.ndim(x) == 1 else {"x": x[:, 0], "y": x[:, 1]}
        parts.append(pd.DataFrame({**{k: [v] * len(mu) for k, v in head.items()}, **cols, "mu": mu}))
    return pd.concat(parts, ignore_index=True)


def write_modes(path, frame) -> None:
    """``frame`` into ``path`` atomically (:func:`infsup_contact.io.write_csv_atomic`); an
    :class:`~.common.OutputError` in one line where the place cannot take it."""
    from ..io import write_csv_atomic
    from .common import OutputError

    try:
        write_csv_atomic(path, frame)
    except OSError as err:
        raise OutputError(f"cannot write --worst-mode {path} ({err.strerror or err})") from None
