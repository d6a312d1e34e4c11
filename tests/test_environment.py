"""The pinned environment: environment.lock covers requirements.in, hashed and reproducible.

Static checks of the two text files (no network, no installs), plus one check that the
running interpreter's packages are the ones the lock pins.
"""
from __future__ import annotations

import importlib.metadata as md
import re
from pathlib import Path

import pytest
from packaging.markers import Marker
from packaging.specifiers import SpecifierSet
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]
REQUIREMENTS = ROOT / "requirements.in"
LOCK = ROOT / "environment.lock"
COMPILE_COMMAND = ("uv pip compile requirements.in --universal --generate-hashes "
                   "--python-version 3.11 -o environment.lock")

# "name[extras] ==1.2 ; marker" -> name; the name is all that requirements.in contributes here
_REQ_NAME = re.compile(r"^\s*([A-Za-z0-9](?:[A-Za-z0-9._-]*[A-Za-z0-9])?)")
_PIN = re.compile(r"^==(?P<version>[^\s;\\]+)$")
_HASH = re.compile(r"^\s+--hash=sha256:[0-9a-f]{64}\s*\\?\s*$")


def normalize(name: str) -> str:
    """PEP 503 normalized project name."""
    return re.sub(r"[-_.]+", "-", name).lower()


def requirement_names() -> list[str]:
    names = []
    for line in REQUIREMENTS.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        m = _REQ_NAME.match(line)
        assert m, f"cannot parse requirements.in line {line!r}"
        names.append(normalize(m.group(1)))
    return names


def lock_entries() -> list[dict]:
    """Every requirement line of the lock with its pin, marker and hash lines."""
    entries = []
    for line in LOCK.read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if line[0].isspace():  # continuation: --hash lines
            assert entries, f"continuation line before any entry: {line!r}"
            if _HASH.match(line):
                entries[-1]["hashes"].append(line.strip())
            continue
        head, _, marker = line.rstrip(" \\").partition(";")
        m = re.match(r"^(?P<name>[A-Za-z0-9][A-Za-z0-9._-]*)(?:\[[^\]]*\])?\s*(?P<spec>.*)$",
                     head.strip())
        assert m, f"cannot parse lock line {line!r}"
        pin = _PIN.match(m.group("spec").strip())
        entries.append(dict(name=normalize(m.group("name")), spec=m.group("spec").strip(),
                            version=pin.group("version") if pin else None,
                            marker=marker.strip() or None, hashes=[], line=line))
    return entries


@pytest.fixture(scope="module")
def entries():
    return lock_entries()


@pytest.fixture(scope="module")
def by_name(entries):
    out: dict[str, list[dict]] = {}
    for e in entries:
        out.setdefault(e["name"], []).append(e)
    return out


def test_requirements_in_parses():
    names = requirement_names()
    assert names, "requirements.in names no package"
    assert len(names) == len(set(names)), f"duplicate names in requirements.in: {names}"
    assert "snakemake" in names and "ngsolve" in names


@pytest.mark.parametrize("name", requirement_names())
def test_direct_dependency_pinned_with_hashes(name, by_name):
    assert name in by_name, f"{name} (requirements.in) is missing from environment.lock"
    for e in by_name[name]:
        assert e["version"] is not None, f"{name} is not pinned with '==' in the lock: {e['line']!r}"
        assert e["hashes"], f"{name}=={e['version']} has no --hash=sha256: line in the lock"


def test_every_lock_entry_pinned_and_hashed(entries):
    """--generate-hashes: every (also transitive) entry is an exact pin with hashes."""
    assert len(entries) > 20
    unpinned = [e["line"] for e in entries if e["version"] is None]
    unhashed = [e["line"] for e in entries if not e["hashes"]]
    assert not unpinned, f"entries not pinned with '==': {unpinned}"
    assert not unhashed, f"entries without --hash lines: {unhashed}"


def test_lock_header_records_compile_command():
    header = []
    for line in LOCK.read_text().splitlines():
        if not line.startswith("#"):
            break
        header.append(line.lstrip("#").strip())
    assert COMPILE_COMMAND in header, (
        f"lock header does not record {COMPILE_COMMAND!r}; header is {header}")


def test_requirements_in_documents_same_compile_command():
    assert COMPILE_COMMAND in REQUIREMENTS.read_text()


def test_snakemake_pin_in_supported_range(by_name):
    pins = [Version(e["version"]) for e in by_name["snakemake"]]
    assert pins
    for v in pins:
        assert v in SpecifierSet(">=9.19,<10"), f"snakemake pinned at {v}, need >=9.19,<10"


def _applies_here(marker: str | None) -> bool:
    return marker is None or Marker(marker).evaluate()


@pytest.mark.parametrize("name", requirement_names())
def test_installed_version_matches_lock(name, by_name):
    """The environment running the tests is the locked one (`make env` installs from the lock)."""
    pins = [e["version"] for e in by_name.get(name, []) if _applies_here(e["marker"])]
    assert len(pins) == 1, f"{name}: expected one lock entry for this interpreter, got {pins}"
    assert md.version(name) == pins[0], (
        f"{name} {md.version(name)} is installed but environment.lock pins {pins[0]}")
