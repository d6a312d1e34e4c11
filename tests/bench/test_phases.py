"""progress.phase / progress.timing: what the breakdown table (bench --phases) is made of."""
import threading

from infsup_contact import progress


def test_phases_are_recorded_only_inside_timing_and_only_by_the_main_thread():
    with progress.phase("eigensolves"):            # nobody records: nothing happens
        pass
    with progress.timing() as times:
        with progress.phase("H Grams"):
            with progress.phase("kernel decision"):
                sum(range(1000))
        worker = threading.Thread(target=lambda: progress.phase("couplings").__enter__())
        worker.start()
        worker.join()
    assert set(times) == {"H Grams", "kernel decision", progress.OTHER}
    with progress.timing() as again:
        pass
    assert set(again) == {progress.OTHER}            # a new recording starts empty


class _Clock:
    """A clock the test moves: wall and CPU seconds and the peak memory advance only when told."""

    def __init__(self):
        self.now = [0.0, 0.0, 0.0]

    def __call__(self):
        return list(self.now)

    def advance(self, wall, cpu, peak=0.0):
        self.now = [a + b for a, b in zip(self.now, (wall, cpu, peak))]


def test_a_phase_inside_another_counts_once(monkeypatch):
    """The outer phase's time excludes the inner one's; ``other`` is the block's time outside
    every phase; the parts add up to the block."""
    clock = _Clock()
    monkeypatch.setattr(progress, "_clocks", clock)
    with progress.timing() as times:
        clock.advance(1, 1)                           # other
        with progress.phase("H Grams"):
            clock.advance(2, 4, 10)
            with progress.phase("couplings"):
                clock.advance(3, 6, 5)
            clock.advance(1, 1)
        with progress.phase("H Grams"):               # a phase entered twice: summed
            clock.advance(1, 2, 1)
    assert times == {"H Grams": (4, 7, 11), "couplings": (3, 6, 5), progress.OTHER: (1, 1, 0)}


def test_every_phase_named_in_the_code_is_a_known_phase():
    import ast
    from pathlib import Path

    src = Path(progress.__file__).parent
    named = set()
    for path in src.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "phase" and node.args
                    and isinstance(node.args[0], ast.Constant)):
                named.add(node.args[0].value)
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "_timed" and isinstance(
                    node.args[0], (ast.Constant, ast.JoinedStr)):
                named.add(node.args[0].value if isinstance(node.args[0], ast.Constant) else "H Grams")
    assert named and named <= set(progress.PHASES), named - set(progress.PHASES)
