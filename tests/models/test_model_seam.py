"""The model seam and the scene registry: the engine never imports a concrete model, every
declared (model, scene) pair runs through the one Γ solve, any other pair is refused in one line."""
from __future__ import annotations

import ast
import contextlib
import functools
import io
from pathlib import Path

import pytest

from helpers.cli import run_in_process

import infsup_contact
from infsup_contact.models import MODELS
from infsup_contact.study.contact.registry import allowed_pairs, scene_ids, scene_spec

PACKAGE = Path(infsup_contact.__file__).parent


def _concrete_model_modules() -> set:
    """Modules that define a registered model (where its side operator lives)."""
    out = set()
    for m in MODELS.values():
        fn = m.side_operator.func if isinstance(m.side_operator, functools.partial) else m.side_operator
        out.add(fn.__module__)
    return out


def _imports(path: Path, package: str) -> set:
    """Absolute module names imported by ``path`` (relative imports resolved)."""
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            mod = ".".join([*base, node.module] if node.module else base)
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
    return out


@pytest.mark.parametrize("stage", ["solvers", "study"])
def test_no_engine_module_imports_a_concrete_model(stage):
    concrete = _concrete_model_modules()
    assert concrete >= {"infsup_contact.models.membranes", "infsup_contact.models.elastic"}
    offenders = {}
    for path in sorted((PACKAGE / stage).glob("*.py")):
        hit = _imports(path, f"infsup_contact.{stage}") & concrete
        if hit:
            offenders[path.name] = sorted(hit)
    assert not offenders, offenders


def _run(argv):
    return run_in_process(argv)


DECLARED = [(m, s) for s in scene_ids() for m in scene_spec(s).models]


@pytest.mark.parametrize("model, scene", DECLARED)
def test_every_declared_pair_runs(model, scene):
    argv = ["contact", "--model", model, "--scene", scene, "--case", "T4", "--k", "2", "--N1", "5", "--N2", "4",
            *(["--n-ref", "10"] if scene_spec(scene).needs_reference else [])]  # a scene without one refuses it
    code, out, err = _run(argv)
    assert code == 0, err
    header, row = out.splitlines()[:2]
    cols = dict(zip(header.split(","), row.split(",")))
    assert cols["scene"] == scene and cols["case"] == "T4"
    assert set(scene_spec(scene).measures) <= set(cols)


@pytest.mark.parametrize("model, scene", [(m, s) for m in MODELS for s in scene_ids() if (m, s) not in DECLARED])
def test_every_other_pair_is_refused_in_one_line(model, scene):
    code, out, err = _run(["contact", "--model", model, "--scene", scene, "--case", "T4", "--k", "1",
                           "--N1", "5", "--N2", "4"])
    assert code == 2 and out == "" and len(err.splitlines()) == 1, err
    assert allowed_pairs() in err


def test_a_manufactured_gap_is_not_an_initial_gap():
    """A manufactured scene's ``gap`` is its exact g = u2 − u1, not data: the Γ solve adds only
    a scene's ``initial_gap`` (the Hertz curvature), so the membranes' pairs carry none."""
    from infsup_contact.contact.contact import contact_pair
    from infsup_contact.study.contact.hertz import hertz_scene
    from infsup_contact.study.contact.scenes import manufactured

    assert contact_pair(manufactured(), 1, "structured", 2, 2).gap is None
    assert hertz_scene(1.0, 0.05).initial_gap(0.5) == 0.0


def test_lambda_values_of_a_saved_reference(tmp_path):
    """A reference written by save_reference (space and λ only) is evaluated like a solution."""
    import numpy as np

    from infsup_contact.contact.contact import lambda_values, solve_contact
    from infsup_contact.study.contact.rows import load_reference, save_reference
    from infsup_contact.study.contact.scenes import membranes

    sol = solve_contact(membranes(), "T3", 1, "structured", 4, 4, time_floor=False)
    save_reference(tmp_path / "ref.npz", sol)
    x = np.linspace(0.1, 0.9, 5)
    assert np.array_equal(lambda_values(load_reference(tmp_path / "ref.npz"), x), sol.pressure(x))
