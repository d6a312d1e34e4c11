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

COLUMNS = ("what", "element", "k", "N", "phase", "cpu_s", "wall_s", "cpu_percent", "share", "peak_added_mib")
MIB = 1024 ** 2


def phase_rows(setup, run) -> list:
    """The breakdown rows of one call ``run()`` (``ours`` on ``setup``, a
    :class:`~.beta_bench.BetaSetup`), in the phases' order, ``other`` and ``total`` last."""
    with progress.timing() as times:
        run()
    cpu = sum(t[1] for t in times.values())
    wall = sum(t[0] for t in times.values())
    names = [p for p in progress.PHASES if p in times] + [p for p in times if p not in progress.PHASES]
    base = dict(what=setup.bench.what, element=setup.mesh_options.get("element", ""), k=setup.k, N=setup.n)

    def row(name, w, c, peak, share):
        return dict(base, phase=name, cpu_s=c, wall_s=w, cpu_percent=100.0 * c / w if w > 0 else 0.0, share=share,
                    peak_added_mib=peak / MIB)
    rows = [row(name, *times[name], times[name][1] / cpu if cpu > 0 else 0.0) for name in names]
    return rows + [row("total", wall, cpu, sum(t[2] for t in times.values()), 1.0)]
