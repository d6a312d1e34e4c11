"""Every row of the Γ table gives a uniform partition: the request checks its spaces on it before
any body exists (``--case all`` on a 3D model, ``verdict``), so ``Interface.uniform_partition`` is
abstract and each shape's Interface provides it. No mesh is built here."""
from __future__ import annotations

import pytest

from infsup_contact.discretization.gamma.interface import Interface
from infsup_contact.discretization.segment.interface import Segment
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.gammas import GAMMA_SHAPES

PARAMS = {"arc": dict(radius=2.0), "cylinder": dict(radius=3.0), "square": dict(cell="trig")}
"""Parameters a row needs (a curved shape's radius), or one that changes its Interface (the cell)."""


def _shapes():
    """(label, Interface) of every row: its defaults, its parameters, each coupling."""
    out = []
    for name, row in GAMMA_SHAPES.items():
        out.append((name, row(**{k: v for k, v in PARAMS.get(name, {}).items() if k == "radius"})))
        if name == "square":
            out.append(("square-trig", row(**PARAMS["square"])))
        for coupling in row.couplings if "coupling" in row.params else ():
            out.append((f"{name}-{coupling}", row(**PARAMS[name], coupling=coupling)))
    return out


SHAPES = _shapes()


def test_every_row_is_listed():
    assert {label.split("-")[0] for label, _ in SHAPES} == set(GAMMA_SHAPES)


@pytest.mark.parametrize("label, gamma", SHAPES, ids=[label for label, _ in SHAPES])
def test_uniform_partition_has_n_cells_per_direction(label, gamma):
    """n cells per direction: n^dim times the cells of one (a face's triangles included), and the
    multiplier mesh of two equal traces is that partition."""
    one = gamma.cells(gamma.uniform_partition(1))
    for n in (2, 3):
        p = gamma.uniform_partition(n)
        assert gamma.cells(p) == one * n ** gamma.dim
        assert gamma.partition_key(gamma.multiplier_partition(p, p)) == gamma.partition_key(p)


@pytest.mark.parametrize("label, gamma", SHAPES, ids=[label for label, _ in SHAPES])
def test_case_all_resolves_on_the_uniform_partition(label, gamma):
    """What ``--case all`` asks of a Γ: the spaces it builds for k = 1, found on one cell per
    direction, include every space of its dimension defined for k whose cells it has."""
    p = gamma.uniform_partition(1)
    built = registry.ids_built_on(1, gamma, gamma.multiplier_partition(p, p))
    assert set(registry.PAPER_CASES) & set(registry.common_ids(1)) <= set(built)


def test_a_shape_without_uniform_partition_is_refused():
    """An Interface that does not say how Γ is cut without a mesh cannot be made (abstract)."""
    members = {name: getattr(Segment, name) for name in Interface.__abstractmethods__ if name != "uniform_partition"}
    Partial = type("Partial", (Interface,), members)
    with pytest.raises(TypeError, match="uniform_partition"):
        Partial()


def test_every_entry_counts_on_a_gamma_of_the_table_it_is_built_on():
    """An entry's dimension count (its structural kernel) is made on a Γ of the table, of a
    dimension it is defined on and whose cells build it: no segment assumed."""
    shapes = [gamma for _, gamma in SHAPES]
    for spec in registry.SPACES.values():
        gamma = spec.count_gamma()
        assert any(gamma is s for s in shapes) or type(gamma) in {type(s) for s in shapes}, spec.id
        assert spec.defined_on(gamma.dim) and gamma.builds(spec), spec.id


def test_no_list_of_spaces_assumes_the_segment():
    """The registry's lists take Γ's dimension from the caller (no default of 1): ``space_ids``
    and ``config_case_ids`` require it, ``ids_valid_for`` filters the ids it is given, and
    ``common_ids`` is what every Γ builds: the ids defined on curves and surfaces alike."""
    import inspect

    from infsup_contact.discretization.spaces.user_spaces import config_case_ids

    for fn, name in ((registry.space_ids, "gamma_dim"), (config_case_ids, "gamma_dim"), (registry.ids_valid_for, "ids")):
        assert inspect.signature(fn).parameters[name].default is inspect.Parameter.empty, fn.__name__
    common = registry.common_ids()
    assert common == [c for c in registry.space_ids(1) if c in registry.space_ids(2)]
    assert set(registry.PAPER_CASES) <= set(common)
    for k in range(1, 5):
        assert registry.common_ids(k) == [c for c in common if registry.SPACES[c].valid_for(k)]
