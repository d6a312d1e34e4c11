"""A new Γ shape takes three files: its ``Interface``, one row of the Γ table and the model builder
that meshes it (the issue's acceptance: "the throwaway Γ shape in 3 files").

The throwaway shape is the paper's segment lifted to height 3: Γ = (0, 1) × {3} between the paper's
squares moved up by 2. Nothing else of the package is touched: the request resolves the new Γ from
the table (no mesh), checks its cases on it, and the engine runs it. β_h is invariant under the
translation (the bilinear forms and the norms do not see it): the rows are the paper's, to the
round-off of the moved vertex coordinates, and the kernels are the same.
"""
from __future__ import annotations

import importlib.util
import sys
import textwrap

import pytest

from infsup_contact.discretization.spaces import gammas
from infsup_contact.models import MODELS
from infsup_contact.solvers.infsup import beta_table
from infsup_contact.solvers.request import BetaRequest, resolve_gamma

FILES = {
    # 1. the Interface: the segment at another height (the trace, partitions, spaces and norms are x's)
    "lifted_segment.py": '''
        from dataclasses import dataclass
        from infsup_contact.discretization.segment.interface import Segment

        @dataclass(frozen=True)
        class LiftedSegment(Segment):
            y: float = 3.0

            def curve(self, mesh, k):
                """A flat Γ: the bodies are meshed as they are."""
    ''',
    # 2. the row of the Γ table: its parameter (the height) with its check
    "lifted_row.py": '''
        from infsup_contact.discretization.spaces.gammas import GammaShape, add_shape
        from infsup_contact.errors import InputError
        from lifted_segment import LiftedSegment

        def check(height=3.0):
            if not height > 1.0:
                raise InputError("height", "a number > 1 (Γ above the paper's)", got=height)

        add_shape(GammaShape("lifted", lambda height=3.0: LiftedSegment(y=float(height)), ("height",), check))
    ''',
    # 3. the model builder that meshes it: the paper's squares moved up to Γ
    "lifted_model.py": '''
        import ngsolve
        from infsup_contact.discretization.segment import meshes
        from infsup_contact.discretization.spaces.gammas import gamma_of
        from infsup_contact.models.contract import Body, Model
        from infsup_contact.models.membranes import side_operator

        def lifted_mesh(family, n, side, *, gamma=None, **options):
            gamma = gamma_of("lifted") if gamma is None else gamma
            ngmesh = meshes.subdomain_mesh(family, n, side, **options).ngmesh.Copy()
            for p in ngmesh.Points():
                p[1] += gamma.y - 1.0
            return Body(ngsolve.Mesh(ngmesh), gamma)

        LIFTED = Model("lifted", side_operator, "the membranes lifted to Γ = (0,1)x{3}", mesh=lifted_mesh,
                       interface=lambda family, gamma="lifted", **options: gamma_of(gamma, **options))
    ''',
}


@pytest.fixture
def lifted(tmp_path, monkeypatch):
    """The three files written and imported (the row registered for this test only)."""
    monkeypatch.setattr(gammas, "GAMMA_SHAPES", dict(gammas.GAMMA_SHAPES))
    monkeypatch.syspath_prepend(str(tmp_path))
    for name, text in FILES.items():
        (tmp_path / name).write_text(textwrap.dedent(text))
    modules = {}
    for name in FILES:  # in order: the shape, its row, its builder
        spec = importlib.util.spec_from_file_location(name[:-3], tmp_path / name)
        modules[name] = importlib.util.module_from_spec(spec)
        monkeypatch.setitem(sys.modules, name[:-3], modules[name])
        spec.loader.exec_module(modules[name])
    return tmp_path, modules["lifted_model.py"].LIFTED


def test_a_new_gamma_shape_is_three_files(lifted):
    where, model = lifted
    assert sorted(p.name for p in where.iterdir() if p.suffix == ".py") == sorted(FILES)
    assert "lifted" in gammas.GAMMA_SHAPES and "lifted" not in MODELS
    request = BetaRequest("structured", 2, 5, 4, ("T3", "R5.4"), norms=("H", "L2"), model=model,
                          gamma=resolve_gamma(model, gamma="lifted"))
    assert request.gamma.y == 3.0  # resolved from the table, no mesh built
    new = beta_table(request)
    old = beta_table(BetaRequest("structured", 2, 5, 4, ("T3", "R5.4"), norms=("H", "L2")))
    assert [(r["case"], r["norm"], r["kernel_dim"], r["dim_M"]) for r in new] == \
           [(r["case"], r["norm"], r["kernel_dim"], r["dim_M"]) for r in old]
    for a, b in zip(new, old):  # translation invariance, to the round-off of the moved coordinates
        assert abs(a["beta"] - b["beta"]) <= 1e-10 * max(b["smallest_nonzero"], 1.0), (a["case"], a["norm"])


def test_the_new_rows_checks_name_their_key(lifted):
    from infsup_contact.errors import InputError

    with pytest.raises(InputError) as err:
        gammas.gamma_of("lifted", height=0.5)
    assert err.value.key == "height"
    with pytest.raises(InputError) as err:
        gammas.gamma_of("helix")
    assert err.value.key == "gamma" and "lifted" in str(err.value)
