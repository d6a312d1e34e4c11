"""The walk of one parameter value: from the command line's entry to the β_h row (a dynamic tracer).

    PYTHONPATH=src python tests/helpers/walk.py case T3 -- beta --case T3 --k 2 --N1 11 --N2 10 --norm H
    PYTHONPATH=src python tests/helpers/walk.py --raw case T3 -- beta --case T3 --k 2 --N1 11 --N2 10 --norm H

runs the command under :func:`sys.setprofile` and follows the value given (``T3``: a string, or a
number typed as on the command line) through the package's functions. Two definitions:

* **resolved** (the default): the value and every object it resolved to (a space from its id, a
  mesh from N): every use of what the user asked for, however far it has been turned into objects;
* **raw** (``--raw``, :class:`RawWalk`): the value as typed only (and the containers holding it):
  where the string or number itself travels, i.e. how far the package carries it before resolving
  it. The review's walks of issue 53 (``case``: 6 modules, 14 hops; ``N1``: 9 modules, 12 hops)
  match this definition best: on the review's tree (b53f071, the 2D request above) the raw walk
  crosses 6 modules for ``case`` and 10 for ``N1``, in 22 and 23 hops (the review's 14 and 12 are
  lower; its rule for a hop is not written down), while the resolved walk
  counts every use of the built space (12 modules, 52 hops for ``case``).

In both:

* a **hop** is a call of a package function that receives a carrier: the value, or what it
  resolved to, as an argument (not as a method's ``self``; directly, or as an element of a tuple/list/set argument, or a
  value of a dict argument);
* a **return** is a hop's return value that carries it on: a carrier, a container holding one,
  or what a hop receiving a scalar carrier resolved it to (a non-container object, e.g. a space
  from its id); each becomes a carrier;
* the **modules** crossed are those of the hops' functions.

In the raw walk a carrier is the value itself or a container holding it, never an object it
resolved to. Only the package's own frames count (not numpy's, not the standard library's); the command line's
parser is entered before the value is in a Python object, so the walk starts at the first function
receiving it. Prints ``modules``, ``hops``, ``returns``, the function that received it most often,
and with ``-v`` every hop in order.
"""
from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

SCALARS = (str, int, float)
CONTAINERS = (tuple, list, set, frozenset, dict)


def _members(value):
    if isinstance(value, dict):
        return list(value.values())
    if isinstance(value, CONTAINERS):
        return list(value)
    return []


class Walk:
    """The carriers and what the tracer saw (module docstring)."""

    def __init__(self, value, root: Path):
        self.value, self.root = value, str(root)
        self.carriers = [value]  # objects compared by identity; the value itself also by equality
        self.hops, self.returns, self.open = [], 0, {}

    def carries(self, obj) -> bool:
        if obj is None or isinstance(obj, bool):
            return False
        if type(obj) is type(self.value) and obj == self.value:
            return True
        return any(obj is c for c in self.carriers)

    def holds(self, obj) -> bool:
        try:
            return self.carries(obj) or any(self.carries(m) for m in _members(obj))
        except Exception:  # an object whose comparison raises (numpy arrays): carries nothing here
            return False

    def __call__(self, frame, event, arg):
        code = frame.f_code
        if not code.co_filename.startswith(self.root):
            return
        if event == "call":
            held = [g for g in _arguments(frame) if self.holds(g)]
            if held:
                module = frame.f_globals.get("__name__", "?")
                self.hops.append((module, getattr(code, "co_qualname", code.co_name)))
                self.open[id(frame)] = any(isinstance(h, SCALARS) for h in held)
        elif event == "return" and id(frame) in self.open:
            scalar = self.open.pop(id(frame))
            if arg is None or isinstance(arg, bool):
                return
            resolved = scalar and not isinstance(arg, (*SCALARS, *CONTAINERS)) and not self.carries(arg)
            if self.holds(arg) or resolved:
                self.returns += 1
                if not self.carries(arg):
                    self.carriers.append(arg)

    def modules(self) -> list:
        """The modules of the hops, in the order first reached."""
        return list(dict.fromkeys(m for m, _ in self.hops))

    def report(self, name: str) -> str:
        short = lambda m: m.replace("infsup_contact.", "")  # noqa: E731
        modules = sorted({short(m) for m, _ in self.hops})
        top = Counter(f"{short(m)}.{f}" for m, f in self.hops).most_common(3)
        return (f"{name}: {len(modules)} modules, {len(self.hops)} hops, {self.returns} returns\n"
                f"  modules: {', '.join(modules)}\n"
                f"  most often: {', '.join(f'{h} x{n}' for h, n in top)}")


class RawWalk(Walk):
    """The value as typed (module docstring, ``--raw``): a hop receives the value itself or a
    container holding it; a return carries it on only as the value or such a container, never as
    an object it was resolved to."""

    def __call__(self, frame, event, arg):
        code = frame.f_code
        if not code.co_filename.startswith(self.root):
            return
        if event == "call":
            if any(self.holds(g) for g in _arguments(frame)):
                self.hops.append((frame.f_globals.get("__name__", "?"), getattr(code, "co_qualname", code.co_name)))
                self.open[id(frame)] = True
        elif event == "return" and self.open.pop(id(frame), False):
            if arg is not None and not isinstance(arg, bool) and self.holds(arg):
                self.returns += 1
                if not self.carries(arg) and isinstance(arg, CONTAINERS):
                    self.carriers.append(arg)


def _arguments(frame) -> list:
    """The arguments a call received (not a method's ``self`` or ``cls``: the object is not passed)."""
    code = frame.f_code
    names = code.co_varnames[:code.co_argcount + code.co_kwonlyargcount
                             + bool(code.co_flags & 0x04) + bool(code.co_flags & 0x08)]
    return [frame.f_locals.get(n) for n in names if n not in ("self", "cls")]


def typed_value(text: str):
    """The value as the command line types it: an integer, else a number, else the string."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            continue
    return text


def trace(value, command: list, raw: bool = False) -> Walk:
    """The walk of ``value`` through ``infsup-contact <command>`` (its output discarded)."""
    import infsup_contact
    from infsup_contact.cli import main as cli_main

    walk = (RawWalk if raw else Walk)(value, Path(infsup_contact.__file__).parent)
    stdout = sys.stdout
    sys.stdout = open("/dev/null", "w")
    sys.setprofile(walk)
    try:
        cli_main(command)
    except SystemExit:
        pass
    finally:
        sys.setprofile(None)
        sys.stdout.close()
        sys.stdout = stdout
    return walk


def main(argv: list) -> int:
    verbose, raw = "-v" in argv, "--raw" in argv
    argv = [a for a in argv if a not in ("-v", "--raw")]
    split = argv.index("--")
    name, command = argv[0], argv[split + 1:]
    walk = trace(typed_value(argv[1]), command, raw)
    print(walk.report(name))
    if verbose:
        print("\n".join(f"  {m.replace('infsup_contact.', '')}.{f}" for m, f in walk.hops))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
