"""Fixtures shared by the test files, and the order in which ``make test`` runs them.

Two things here only make the suite faster; no test asserts less because of them:

* ``SLURM_CONF``: every ``snakemake`` process imports the Slurm executor plugin, which at import
  asks ``scontrol show config`` for MinJobAge (snakemake_executor_plugin_slurm.job_status_query).
  With Slurm's client tools installed and no controller answering (a machine where
  ``tests/slurm/standup.sh`` ran once and its daemons are stopped) that call waits ~9 s
  for its connection to fail, in each of the ~40 Snakemake runs of the suite. Unless the
  Slurm tests are selected (``-m slurm``) or ``SLURM_CONF`` is set already, the session points
  ``SLURM_CONF`` at an empty file: ``scontrol`` then fails at once and the plugin takes the
  branch it takes after the wait (MinJobAge unknown → ``None``); nothing else reads it.
* ``slow_first``: tests so marked are moved to the front of the collection, so that under
  ``-n 2`` they start first instead of forming a tail on one worker. Tests sharing an expensive
  run build it once per pytest run through :func:`helpers.once.once` (a file lock), so any
  worker may take any test: no scheduling group, nothing of pytest's or xdist's internals.
"""
import os

import pytest


def pytest_configure(config):
    # progress on stderr (infsup_contact/progress.py) shows after a delay: with the default 3 s a
    # test's stderr would depend on the machine's speed; tests/cli/test_progress.py sets it to 0
    os.environ.setdefault("INFSUP_PROGRESS_DELAY", "3600")
    if "slurm" not in (config.getoption("markexpr", "") or "") and "SLURM_CONF" not in os.environ:
        os.environ["SLURM_CONF"] = os.devnull


def pytest_collection_modifyitems(config, items):
    """Marked ``slow_first`` to the front, otherwise the collection order (a stable sort, the
    same on every xdist worker, as xdist requires). Marked ``machines`` (the suite's own tests
    rerun under other OpenBLAS/MKL code paths, ~5 min of CPU) run only under ``-m machines``:
    ``.ci/run`` runs them beside ``make test``, which stays within its 10 minutes."""
    from helpers.markers import asked_for

    if not asked_for(config.getoption("markexpr", "") or "", "machines"):
        skip = pytest.mark.skip(reason="machines test: runs only under `pytest -m machines` (.ci/run runs it)")
        for item in items:
            if item.get_closest_marker("machines"):
                item.add_marker(skip)
    items.sort(key=lambda item: item.get_closest_marker("slow_first") is None)


@pytest.fixture(autouse=True)
def registry_as_found():
    """Checking or loading a config, or a ``--space`` run in process, registers user spaces:
    every test leaves the registry as it found it, so no test depends on which tests ran
    before it in the same worker (a ``--space`` test left ``P0-2h`` registered for the
    next file's catalogue checks)."""
    from infsup_contact.discretization.spaces.registry import SPACES
    from infsup_contact.discretization.spaces.user_spaces import forget_since

    before = set(SPACES)
    yield
    forget_since(before)
