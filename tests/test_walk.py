"""The walk of a typed case id (``tests/helpers/walk.py``): resolved once, at the request's edge.

The raw walk follows the id as typed; the request (:class:`~infsup_contact.solvers.request.BetaRequest`,
built in ``solvers/request``) resolves it to its registry entry, so no other module of ``solvers/``
receives the string. The resolved walk of the same command (what the id became: its entry, the
space) does reach the engine: the tracer sees those modules, so the raw walk's silence there is
the id's absence, not the tracer's blindness.
"""
import pytest

from helpers.walk import trace

EDGE = "infsup_contact.solvers.request"
"""The module that builds the request: the edge, where the id may be read."""

REQUESTS = {
    "2D": ["beta", "--case", "T3", "--k", "1", "--N1", "3", "--N2", "2", "--norm", "H"],
    "3D": ["beta", "--model", "membranes3d", "--case", "DUAL-Q9", "--k", "2", "--N1", "2", "--N2", "2", "--norm", "H"],
}


def _engine(walk) -> list:
    return [f"{m}.{f}" for m, f in walk.hops if m.startswith("infsup_contact.solvers.") and m != EDGE]


@pytest.mark.parametrize("model", sorted(REQUESTS))
def test_a_typed_case_id_never_reaches_the_engine(model):
    command = REQUESTS[model]
    case = command[command.index("--case") + 1]
    raw = trace(case, command, raw=True)
    checks = [f for m, f in raw.hops if f == "check_on_gamma"]
    assert checks == ["check_on_gamma"], raw.hops  # the id reached the request, and was checked on Γ once
    assert _engine(raw) == [], raw.hops
    assert _engine(trace(case, command)), "the resolved walk reaches the engine: the tracer sees it"
