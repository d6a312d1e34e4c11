"""The walk of one parameter value: from the command line's entry to the β_h row (a dynamic tracer).

    PYTHONPATH=src python tests/helpers/walk.py case T3 -- beta --case T3 --k 2 --N1 11 --N2 10 --norm H

runs the command under :func:`sys.setprofile` and follows the value given (``T3``: a string, or a
number typed as on the command line) through the package's functions:

* a **hop** is a call of a package function that receives a carrier: the value, or what it
  resolved to, as an argument (not as a method's ``self``; directly, or as an element of a tuple/list/set argument, or a
  value of a dict argument);
* a **return** is a hop's return value that carries it on: a carrier, a container holding one,
  or what a hop receiving a scalar carrier resolved it to (a non-container object, e.g. a space
  from its id); each becomes a carrier;
* the **modules** crossed are those of the hops' functions.

Only the package's own frames count (not numpy's, not the standard library's); the command line's
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
            names = code.co_varnames[:code.co_argcount + code.co_kwonlyargcount
                                     + bool(code.co_flags & 0x04) + bool(code.co_flags & 0x08)]
            got = [frame.f_locals.get(n) for n in names if n not in ("self", "cls")]  # a method's object: not passed
            held = [g for g in got if self.holds(g)]
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

    def report(self, name: str) -> str:
        short = lambda m: m.replace("infsup_contact.", "")  # noqa: E731
        modules = sorted({short(m) for m, _ in self.hops})
        top = Counter(f"{short(m)}.{f}" for m, f in self.hops).most_common(3)
        return (f"{name}: {len(modules)} modules, {len(self.hops)} hops, {self.returns} returns\n"
                f"  modules: {', '.join(modules)}\n"
                f"  most often: {', '.join(f'{h} x{n}' for h, n in top)}")


def main(argv: list) -> int:
    verbose = "-v" in argv
    argv = [a for a in argv if a != "-v"]
    split = argv.index("--")
    name, raw, command = argv[0], argv[1], argv[split + 1:]
    value = raw
    for kind in (int, float):
        try:
            value = kind(raw)
            break
        except ValueError:
            continue
    import infsup_contact
    from infsup_contact.cli import main as cli_main

    walk = Walk(value, Path(infsup_contact.__file__).parent)
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
    print(walk.report(name))
    if verbose:
        print("\n".join(f"  {m.replace('infsup_contact.', '')}.{f}" for m, f in walk.hops))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
