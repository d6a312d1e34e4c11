"""Progress of a long request on stderr: what runs now, on which space and mesh, for how long.

The library's loops say where they are through two calls: :func:`steps` (iterate over a loop,
one step per item: ``space T3 (3/12)``) and :func:`note` (a stage inside the current step:
``side 1 of 2 (N1=16): meshing, assembling, factorizing``). With no reporter installed — the
default, so a library or :mod:`infsup_contact.api` user gets no output — both cost one global
read. ``infsup-contact`` installs one (:func:`reporting`) around a request's computation (after
its checks: a refusal is still one line), unless ``--quiet``:

* stderr a terminal: one tqdm bar (the outermost loop's count, the elapsed time, where it is);
* otherwise (CI logs, pipes, files): one plain line per step or stage, no carriage return::

    infsup-contact: [12.3 s] beta membranes3d k=2 N1=16 N2=16: space T3 (3/12), norm H: eigenproblem

A request done within :func:`default_delay` seconds (3; ``INFSUP_PROGRESS_DELAY``) prints nothing,
as tqdm's own ``delay``: a quick request's stderr stays empty; a longer one's first line (or bar)
says where it is when the delay ends. In plain mode a step longer than :data:`HEARTBEAT` seconds is
said again with the new time, so a slow run is told from a hung one in a log too.

Where the time goes: :func:`phase` marks a phase of a β_h request (:data:`PHASES`) and
:func:`timing` records their CPU and wall seconds (``bench --what face --phases``,
:mod:`infsup_contact.bench.phases`); outside :func:`timing` a phase costs one global read.
"""
from __future__ import annotations

import os
import sys
import threading
import time
from contextlib import contextmanager

PREFIX = "infsup-contact"
DELAY = 3.0
"""Seconds a request runs before its progress is shown (``INFSUP_PROGRESS_DELAY`` overrides)."""
HEARTBEAT = 30.0
"""Plain mode: seconds after which an unchanged step is said again, with its elapsed time."""
TICK = 0.5
"""Seconds between the clock thread's looks (the bar's elapsed time, the delay, the heartbeat)."""

_reporter = None  # module-level, not per thread: the producers' stage reports from its threads


def default_delay() -> float:
    """:data:`DELAY`, or ``INFSUP_PROGRESS_DELAY`` (seconds >= 0) where set to a number."""
    try:
        return max(0.0, float(os.environ.get("INFSUP_PROGRESS_DELAY", DELAY)))
    except ValueError:
        return DELAY


class _Frame:
    """One loop being iterated: ``what label (index/total)``."""

    def __init__(self, what: str, total):
        self.what, self.total, self.index, self.label = what, total, 0, ""

    def text(self) -> str:
        count = f" ({self.index}/{self.total})" if self.total else ""
        return f"{self.what} {self.label}{count}".strip()


class Reporter:
    """Where a request is, on ``stream``: a tqdm bar (``bar=True``) or plain lines.

    Parameters
    ----------
    title : str
        The request, first in every line (``beta membranes3d k=2 N1=16 N2=16``).
    stream : file, optional
        Default ``sys.stderr``.
    bar : bool, optional
        Default: whether ``stream`` is a terminal.
    delay : float, optional
        Seconds before anything is shown (default :func:`default_delay`).
    """

    def __init__(self, title: str, stream=None, bar: bool | None = None, delay: float | None = None):
        self.title = title
        self.stream = sys.stderr if stream is None else stream
        self.bar = _isatty(self.stream) if bar is None else bar
        self.delay = default_delay() if delay is None else float(delay)
        self.t0 = time.perf_counter()
        self._lock = threading.RLock()
        self._local = threading.local()
        self._where = ""          # the last step or stage said, without the time
        self._outer = (0, None)   # the outermost loop's (index, total): the bar's count
        self._said_at = None      # plain mode: when the last line was written (None: nothing yet)
        self._tqdm = None
        self._stop = threading.Event()
        self._clock = threading.Thread(target=self._run_clock, daemon=True, name="infsup-progress")

    # -------------------------------------------------------------- what the library calls
    def frames(self) -> list:
        """The loops this thread is in, outermost first."""
        if not hasattr(self._local, "frames"):
            self._local.frames = []
        return self._local.frames

    def event(self, message: str | None = None) -> None:
        """Say where this thread is now: its loops, then ``message`` (a stage) if given."""
        frames = self.frames()
        where = ", ".join(f.text() for f in frames)
        where = ": ".join(p for p in (where, message) if p)
        with self._lock:
            self._where = where
            if frames and threading.current_thread() is threading.main_thread():
                self._outer = (frames[0].index, frames[0].total)
            self._show()

    # -------------------------------------------------------------- output
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def line(self) -> str:
        """The plain line of where the request is now."""
        return f"{PREFIX}: [{self.elapsed():.1f} s] " + ": ".join(p for p in (self.title, self._where) if p)

    def _show(self, heartbeat: bool = False) -> None:
        """Write the current state (called under the lock), once the delay has passed."""
        if self.elapsed() < self.delay:
            return
        if self.bar:
            self._draw()
        elif self._said_at is None or not heartbeat or time.perf_counter() - self._said_at >= HEARTBEAT:
            self._write(self.line() + "\n")
            self._said_at = time.perf_counter()

    def _draw(self) -> None:
        from tqdm import tqdm

        if self._tqdm is None:
            # a terminal that reports no width (0 columns) would make tqdm drop the bar format
            self._tqdm = tqdm(total=None, file=self.stream, desc=self.title, leave=False, mininterval=0, miniters=0,
                              bar_format="{desc} [{elapsed}]",
                              **({"dynamic_ncols": True} if _columns(self.stream) else {"ncols": 100}))
            self._tqdm.start_t = self._tqdm.last_print_t = time.time() - self.elapsed()  # the request's time
        index, total = self._outer
        self._tqdm.total, self._tqdm.n = total, index
        self._tqdm.bar_format = ("{desc}: {percentage:3.0f}%|{bar:20}| {n_fmt}/{total_fmt} [{elapsed}]{postfix}"
                                 if total else "{desc} [{elapsed}]{postfix}")  # tqdm puts ", " before the postfix
        self._tqdm.set_postfix_str(self._where, refresh=True)

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # stderr closed or full: progress is not worth failing for
            pass

    def _run_clock(self) -> None:
        """Show the state when the delay ends, keep the bar's time running, the plain heartbeat."""
        while not self._stop.wait(TICK):
            with self._lock:
                if self._where or self.elapsed() >= self.delay:
                    self._show(heartbeat=True)

    def start(self) -> "Reporter":
        self._clock.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._clock.is_alive():
            self._clock.join()
        with self._lock:
            if self._tqdm is not None:
                self._tqdm.close()
                self._tqdm = None


def _columns(stream) -> int:
    """The terminal's width (0: unknown)."""
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, OSError, ValueError):
        return 0


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


# ------------------------------------------------------------------ the library's calls
def steps(items, what: str, label=str, total: int | None = None):
    """Iterate over ``items``, each one step ``what label(item) (i/n)`` of the active reporter
    (none: just the items). ``total`` defaults to ``len(items)`` where it has one."""
    reporter = _reporter
    if reporter is None:
        yield from items
        return
    if total is None:
        try:
            total = len(items)
        except TypeError:
            total = None
    frames = reporter.frames()
    frame = _Frame(what, total)
    frames.append(frame)
    try:
        for i, item in enumerate(items, 1):
            frame.index, frame.label = i, label(item)
            reporter.event()
            yield item
    finally:
        frames.remove(frame)


def note(message: str) -> None:
    """Say the stage of the current step (``factorizing side 1 of 2``); nothing with no reporter."""
    reporter = _reporter
    if reporter is not None:
        reporter.event(message)


def detach() -> None:
    """In a forked worker process (:mod:`infsup_contact.solvers.side_by_side`): report nothing and
    time no phase (the parent says what finished and counts the workers' CPU in its phase)."""
    global _reporter, _phases
    _reporter, _phases = None, None


def active() -> bool:
    """Whether a request's progress is being reported (an :mod:`infsup_contact.api` call: no)."""
    return _reporter is not None


@contextmanager
def reporting(title: str, quiet: bool = False, stream=None, bar: bool | None = None, delay: float | None = None):
    """Report the progress of the code run inside on ``stream`` (:class:`Reporter`); with ``quiet``
    nothing is installed. The previous reporter (usually none) is restored after."""
    global _reporter
    if quiet or (stream is None and sys.stderr is None):
        yield None
        return
    previous, reporter = _reporter, Reporter(title, stream, bar, delay).start()
    _reporter = reporter
    try:
        yield reporter
    finally:
        _reporter = previous
        reporter.close()


# ------------------------------------------------------------------ where the time goes
PHASES = ("sides: mesh, assembly, factorization", "couplings", "H Grams", "L2 Grams",
          "kernel decision, Grams split and factorized", "interface terms", "β with v1 = 0", "eigensolves",
          "spaces side by side")
"""The phases of a β_h request (:func:`phase`), in the order they run; the rest is ``other``. The
spaces that run two at a time (:mod:`infsup_contact.solvers.side_by_side`) count as the last one."""
OTHER = "other"

_phases = None  # {phase: [wall s, CPU s, peak growth B]} while :func:`timing` records, else None
_phase_stack: list = []


def _clocks() -> list:
    """[wall s, CPU s of the process and of its ended worker processes, the process's peak resident
    bytes so far] now (a worker's memory is its own: not in this peak)."""
    import resource

    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux
    workers = resource.getrusage(resource.RUSAGE_CHILDREN)
    return [time.perf_counter(), time.process_time() + workers.ru_utime + workers.ru_stime, float(peak)]


@contextmanager
def phase(name: str):
    """Count the wall and CPU time of the code inside as ``name`` while :func:`timing` records
    (else nothing: one global read), and how far it raised the process's peak resident memory.
    The CPU time is the process's (every thread: MKL's, the concurrent tasks'), so only the main
    thread records; a phase inside another counts in its own name only (the outer one excludes it)."""
    record = _phases
    if record is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    _phase_stack.append([0.0, 0.0, 0.0])  # what the phases nested in this one took
    start = _clocks()
    try:
        yield
    finally:
        took = [b - a for a, b in zip(start, _clocks())]
        inner = _phase_stack.pop()
        entry = record.setdefault(name, [0.0, 0.0, 0.0])
        for i in range(3):
            entry[i] += took[i] - inner[i]
            if _phase_stack:
                _phase_stack[-1][i] += took[i]


@contextmanager
def timing():
    """Record the :func:`phase` measures of the code inside; yields the dict {phase: (wall s, CPU s,
    growth of the peak resident memory in bytes)}, filled when the block ends, with ``other`` = the
    block's own measures outside every phase."""
    global _phases
    previous, record, out = _phases, {}, {}
    _phases = record
    _phase_stack.clear()
    start = _clocks()
    try:
        yield out
    finally:
        took = [b - a for a, b in zip(start, _clocks())]
        _phases = previous
        out.update({name: tuple(v) for name, v in record.items()})
        out[OTHER] = tuple(took[i] - sum(v[i] for v in record.values()) for i in range(3))
