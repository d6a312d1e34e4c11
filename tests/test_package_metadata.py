"""pyproject.toml's dependencies against the code and the lock (static, cheap): every third-party
module src/ imports is a declared dependency (issue 50: a clean `pip install .` had no yaml, no
skfem), and environment.lock's pins lie within the declared bounds (the tested set is one the
package admits). The install itself is tested by `pytest -m package` (tests/package/)."""
from __future__ import annotations

import ast
import importlib.metadata as md
import re
import sys
import tomllib
from pathlib import Path

from packaging.markers import default_environment
from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
NOT_DECLARED = {
    "qpsolvers": "bench/peers.solve_qpsolvers: a cross-check the tests call, no subcommand",
    "petsc4py": "systems/hb_petsc.read_petsc: used when importable, else its own PETSc reader",
}
"""Modules src/ imports that a plain install does not bring, and why (each in an extra, tested below)."""


def normalize(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def imported_modules() -> set[str]:
    """Top-level names of every import in src/ that is neither the standard library nor ours."""
    names = set()
    for path in (ROOT / "src").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return {n for n in names if n not in sys.stdlib_module_names and n != "infsup_contact"}


def declared() -> dict[str, Requirement]:
    return {normalize(r.name): r for r in map(Requirement, PROJECT["dependencies"])}


def test_every_imported_module_is_a_declared_dependency():
    owners = md.packages_distributions()
    deps = declared()
    missing = []
    for module in sorted(imported_modules() - set(NOT_DECLARED)):
        dists = {normalize(d) for d in owners.get(module, [module])}
        if not any(d in deps for d in dists):
            missing.append(f"{module} ({', '.join(sorted(dists))})")
    assert not missing, f"src/ imports modules pyproject.toml does not declare: {missing}"


def test_every_optional_import_is_an_extra():
    extras = {normalize(Requirement(r).name) for reqs in PROJECT["optional-dependencies"].values() for r in reqs}
    assert {normalize(m) for m in NOT_DECLARED} <= extras, f"not in any extra: {set(NOT_DECLARED)}"


def test_every_dependency_has_bounds():
    for name, req in declared().items():
        ops = {spec.operator for spec in req.specifier}
        assert ">=" in ops, f"{name}: no lower bound"
        assert "<" in ops or name == "mkl", f"{name}: no upper bound"  # mkl: calendar versions (pyproject)


def test_the_locks_pins_satisfy_the_bounds():
    """Each dependency the lock pins for this interpreter is admitted by its specifier."""
    pins = {}
    env = default_environment()
    for line in (ROOT / "environment.lock").read_text().splitlines():
        m = re.match(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)\s*(?:;\s*(.*?))?\s*\\?$", line)
        if m and (not m.group(3) or Requirement(f"x; {m.group(3)}").marker.evaluate(env)):
            pins[normalize(m.group(1))] = m.group(2)
    checked = 0
    for name, req in declared().items():
        if name in pins and (req.marker is None or req.marker.evaluate(env)):
            assert req.specifier.contains(pins[name], prereleases=True), f"{name}=={pins[name]} outside {req.specifier}"
            checked += 1
    assert checked >= 10  # the lock pins the stack (numpy, scipy, ngsolve, ...)


def test_mkl_only_where_its_wheel_and_loader_are():
    marker = declared()["mkl"].marker
    assert marker is not None
    linux = dict(default_environment(), sys_platform="linux", platform_machine="x86_64")
    assert marker.evaluate(linux)
    for other in ({"sys_platform": "darwin", "platform_machine": "arm64"},
                  {"sys_platform": "linux", "platform_machine": "aarch64"},
                  {"sys_platform": "win32", "platform_machine": "AMD64"}):
        assert not marker.evaluate(dict(linux, **other)), other
