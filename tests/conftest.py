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
  ``-n 2 --dist loadgroup`` (pyproject addopts) they start first instead of forming a tail on
  one worker; tests marked ``xdist_group`` share one worker (and so their module fixtures).
"""
import os

import pytest


def pytest_configure(config):
    if "slurm" not in (config.getoption("markexpr", "") or "") and "SLURM_CONF" not in os.environ:
        os.environ["SLURM_CONF"] = os.devnull


def pytest_collection_modifyitems(config, items):
    """Marked ``slow_first`` to the front, otherwise the collection order (a stable sort, the
    same on every xdist worker); on an xdist worker under ``--dist loadgroup``, the
    ``xdist_group`` names put on the node ids (see :func:`_group_suffix`)."""
    items.sort(key=lambda item: item.get_closest_marker("slow_first") is None)
    if getattr(config.option, "loadgroup", False):
        for item in items:
            _group_suffix(item)


def _group_suffix(item):
    """``nodeid@group`` for a test marked ``xdist_group(group)``: what pytest-xdist's worker does
    (xdist/remote.py, ``item._nodeid = ...``) and what its LoadGroupScheduling reads on the
    controller. Since pytest 9 a node keeps its id as a ``NodeId`` in ``item._id`` and
    ``_nodeid`` is read by nothing, so xdist 3.8's suffix is lost and every test is a group of
    its own; this sets it where pytest keeps it. Without the structure expected, nothing is done
    (the tests then spread as under ``--dist load``, each worker making its own module fixtures)."""
    names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                    for m in item.iter_markers("xdist_group")})
    node_id = getattr(item, "_id", None)
    if not names or node_id is None or not hasattr(type(node_id), "parse"):
        return
    suffix = "@" + "_".join(names)
    if not item.nodeid.endswith(suffix):
        item._id = type(node_id).parse(item.nodeid + suffix)


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
