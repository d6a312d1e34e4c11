"""A result built once per pytest run, also under pytest-xdist: the first worker to ask builds it
under a file lock (the stdlib's ``fcntl.flock``) in the run's shared temporary folder, the others
wait and read it. Tests sharing an expensive run (a Snakemake workflow, the machine sweeps) then
need no scheduling group: any worker may run any of them.

The shared folder is the parent of the worker's base temporary folder, the recipe of
pytest-xdist's documentation ("Making session-scoped fixtures execute only once"); without xdist
the base folder itself.
"""
from __future__ import annotations

import fcntl
import json
import os
from pathlib import Path
from typing import Callable


def shared_root(tmp_path_factory) -> Path:
    """The temporary folder every worker of this run sees."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def once(tmp_path_factory, name: str, build: Callable[[Path], object]):
    """``build(folder)`` run once per pytest run in ``<shared root>/name``; its JSON-able result
    (or its failure, re-raised in every test that asks) is returned to every caller.

    Parameters
    ----------
    tmp_path_factory : pytest.TempPathFactory
        The session's factory (the fixture of the same name).
    name : str
        Folder and lock name; one per shared result.
    build : callable
        ``build(folder) -> result``; ``folder`` exists and is empty when it is called.
    """
    root = shared_root(tmp_path_factory)
    folder, done = root / name, root / f"{name}.json"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes, also if build raises
        if not done.exists():
            folder.mkdir()
            try:
                record = {"ok": True, "value": build(folder)}
            except Exception as err:  # a failed build fails every test sharing it (not rebuilt by each)
                record = {"ok": False, "error": f"{type(err).__name__}: {err}"}
            done.write_text(json.dumps(record))
    record = json.loads(done.read_text())
    if not record["ok"]:
        raise RuntimeError(f"the shared run {name!r} failed: {record['error']}")
    return record["value"]
