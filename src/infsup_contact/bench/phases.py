"""Where a β_h request's time goes: the breakdown table of one ``ours`` run, per phase.

    infsup-contact bench --what face --N 16 --k 2 --phases results/benchmarks/face_phases.csv

One end-to-end run (:func:`~.beta_bench.beta_ours`, as ``infsup-contact beta --case all --norm
all``) under :func:`infsup_contact.progress.timing`: per phase of :data:`~infsup_contact.progress.PHASES`
(and ``other``: imports, meshes of Γ, spaces, rows) the CPU seconds of the process (every thread:
MKL's, the concurrent tasks'), the wall seconds, CPU % = CPU / wall (above 100: more than one core
busy) and the share of the run's CPU. docs/performance.md's table "Where the time goes" is generated
from it (workflow/scripts/docs_performance.py).
"""
from __future__ import annotations

from .. import progress

COLUMNS = ("what", "element", "k", "N", "phase", "cpu_s", "wall_s", "cpu_percent", "share")


def phase_rows(setup, run) -> list:
    """The breakdown rows of one call ``run()`` (``ours`` on ``setup``, a
    :class:`~.beta_bench.BetaSetup`), in the phases' order, ``other`` and ``total`` last."""
    with progress.timing() as times:
        run()
    cpu = sum(c for _, c in times.values())
    wall = sum(w for w, _ in times.values())
    names = [p for p in progress.PHASES if p in times] + [p for p in times if p not in progress.PHASES]
    base = dict(what=setup.bench.what, element=setup.mesh_options.get("element", ""), k=setup.k, N=setup.n)
    rows = [dict(base, phase=name, cpu_s=c, wall_s=w, cpu_percent=100.0 * c / w if w > 0 else 0.0,
                 share=c / cpu if cpu > 0 else 0.0) for name in names for w, c in [times[name]]]
    return rows + [dict(base, phase="total", cpu_s=cpu, wall_s=wall, cpu_percent=100.0 * cpu / wall if wall > 0
                        else 0.0, share=1.0)]
