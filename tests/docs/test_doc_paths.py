"""Every file, folder and module path the docs name in backticks exists (``src/...``,
``study/verdict.py``, ``la/bottom.bottom_pencil``, ``tests/...``), and a dotted name after a
module is defined in it. A path may be written from the repository root or from any folder of
it (``segment/dual.py`` is ``src/infsup_contact/discretization/segment/dual.py``)."""
from __future__ import annotations

import ast
import fnmatch
import re
from functools import lru_cache

import pytest
from helpers.doc_blocks import PAGES, ROOT

EXTERNAL = {"PetscBinaryIO.py", "actions/runner", "actions/checkout@v4", "infsup-contact-verdict/1",
            "route / ours"}
"""Names of other projects' files (PETSc's reader, GitHub's runner) and formats, not ours."""

_SKIP_DIRS = {".git", ".venv", "results", ".snakemake", "build", "__pycache__", "node_modules"}
_PLACEHOLDER = re.compile(r"[{}<>…]|\b(NAME|DIR|FILE|RULE|GROUP|SPACE)\b")
_OUTPUT_ROOTS = ("results/", "/", ".snakemake/", ".venv/", "~", ".calculix/")


@lru_cache(maxsize=1)
def repo_paths() -> tuple:
    """Every file and folder of the repository (relative, posix), outputs and environments left out."""
    out = []
    for path in ROOT.rglob("*"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in _SKIP_DIRS or any(p.endswith(".egg-info") or p == "__pycache__" for p in rel.parts):
            continue
        out.append(rel.as_posix() + ("/" if path.is_dir() else ""))
    return tuple(out)


def named_paths(text: str):
    """The backticked words that name a path: one word with a '/' or ending in .py."""
    for token in re.findall(r"`([^`\n]+)`", text):
        token = re.sub(r"\(.*\)$", "", token.strip())
        if " " in token or token in EXTERNAL or token.startswith(_OUTPUT_ROOTS) or _PLACEHOLDER.search(token):
            continue
        if ":" in token or token.startswith("-") or "=" in token:
            continue
        if "/" in token or re.search(r"\w\.py\b", token):
            yield token


def _split(token: str):
    """(path part, dotted names after a module): ``la/bottom.bottom_pencil`` → ('la/bottom.py', ['bottom_pencil'])."""
    head, _, last = token.rpartition("/")
    if "." in last and not re.search(r"\.(py|md|yaml|yml|smk|tex|csv|json|npz|rst|txt|lock|in)$", last):
        name, *attrs = last.split(".")
        if attrs and attrs[0] == "py":
            return token, []
        return (f"{head}/" if head else "") + f"{name}.py", attrs
    return token, []


def resolve(token: str) -> list[str]:
    """The repository paths ``token`` may mean (written from the root or from any folder)."""
    path, _ = _split(token)
    candidates = [path, path + ".py", path.rstrip("/") + "/"] if not path.endswith((".py", "/")) else [path]
    found = []
    for rel in repo_paths():
        for c in candidates:
            if any(ch in c for ch in "*?["):
                if fnmatch.fnmatch(rel, c) or fnmatch.fnmatch(rel, "*/" + c):
                    found.append(rel)
            elif rel == c or rel.endswith("/" + c):
                found.append(rel)
    return found


def _defines(module: str, attrs: list[str]) -> bool:
    tree = ast.parse((ROOT / module).read_text(encoding="utf-8"))
    body = tree.body
    for attr in attrs:
        names = {}
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names[node.name] = getattr(node, "body", [])
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                    for t in ast.walk(target):
                        if isinstance(t, ast.Name):
                            names[t.id] = []
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names.update({(a.asname or a.name).split(".")[0]: [] for a in node.names})
        if attr not in names:
            return False
        body = names[attr]
    return True


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_path_the_docs_name_exists(page):
    missing = []
    for token in sorted(set(named_paths(page.read_text(encoding="utf-8")))):
        found = resolve(token)
        _, attrs = _split(token)
        if not found:
            missing.append(token)
        elif attrs and not any(f.endswith(".py") and _defines(f, attrs) for f in found):
            missing.append(f"{token} (not defined in {', '.join(found)})")
    assert not missing, f"{page.name} names paths that do not exist: {missing}"


def test_the_resolver_finds_and_misses():
    """The resolver itself: a real module, a dotted name in it, a file under a folder, and a
    name that is not there."""
    assert resolve("la/bottom.bottom_pencil") == ["src/infsup_contact/la/bottom.py"]
    assert _defines("src/infsup_contact/la/bottom.py", ["bottom_pencil"])
    assert not _defines("src/infsup_contact/la/bottom.py", ["no_such_function"])
    assert resolve("segment/dual.py") == ["src/infsup_contact/discretization/segment/dual.py"]
    assert resolve("study/face_patch.py") == []
    assert list(named_paths("`study/x.py` `results/a.csv` `FILE.py:NAME` `a b/c`")) == ["study/x.py"]
