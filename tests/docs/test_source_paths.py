"""Every repository path that prose names exists, backticked or not: the docs pages and the
README, the comments and docstrings of ``src/`` and ``workflow/scripts/``, the rule files, the
Snakefiles and the config files. A path is a word with a ``/`` ending in ``.py``, ``.smk``,
``.yaml`` or ``.md`` (``workflow/rules/models.smk``, ``study/beta/batch_rows.py``,
``../scripts/model_job.py``), or any ``*.smk`` word: a rule file is often named bare.

A path is found when it is the repository path of a file, or the tail of one
(``rules/models.smk``, ``plans/membranes3d.py``), or, written with ``./`` or ``../``, a file
relative to the naming file's folder. Placeholders (``DIR/``, ``path/to/``, a ``{wildcard}``,
``<name>``, a glob) and outputs (``results/``) are not paths of the repository.
"""
from __future__ import annotations

import ast
import io
import re
import tokenize
from functools import lru_cache
from pathlib import Path

import pytest
from helpers.doc_blocks import ROOT

PATH = re.compile(r"(?<![\w./-])((?:\.{1,2}/)*(?:[\w.-]+/)*[\w.-]+\.(?:py|smk|yaml|md))(?![\w/-])")
PLACEHOLDER = re.compile(r"[{}<>*?\[\]…]|\b(DIR|NAME|FILE|path/to|test_x)\b|^(a|exports)/")
OUTPUTS = ("results/", ".snakemake/", ".venv/", "/")
EXTERNAL = {"lib/petsc/bin/PetscBinaryIO.py"}
"""Other projects' files (PETSc's reference reader), not ours."""
_SKIP = {".git", ".venv", "results", ".snakemake", "build", "__pycache__", ".calculix"}


@lru_cache(maxsize=1)
def repo_files() -> frozenset:
    """Every file of the repository (relative, posix), outputs and environments left out."""
    return frozenset(p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*")
                     if p.is_file() and not _SKIP & set(p.relative_to(ROOT).parts)
                     and not any(part.endswith(".egg-info") for part in p.relative_to(ROOT).parts))


def exists(token: str, where: Path) -> bool:
    """Whether ``token``, named in the file ``where``, is a file of the repository."""
    if token.startswith(("./", "../")):
        return (where.parent / token).resolve().relative_to(ROOT).as_posix() in repo_files()
    return any(f == token or f.endswith("/" + token) for f in repo_files())


def named_paths(text: str):
    """The words of ``text`` that name a path of the repository (placeholders, outputs left out)."""
    for token in PATH.findall(text):
        token = token.rstrip(".")
        if "/" not in token and not token.endswith(".smk"):
            continue
        if token in EXTERNAL or token.startswith(OUTPUTS) or PLACEHOLDER.search(token):
            continue
        yield token


def python_prose(source: str):
    """(line, text) of the comments and docstrings of a Python source: where it names files for
    a reader (its string literals are data: a message may show a placeholder path)."""
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            yield tok.start[0], tok.string
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = node.body[0] if node.body else None
            if isinstance(doc, ast.Expr) and isinstance(doc.value, ast.Constant) and isinstance(doc.value.value, str):
                for i, line in enumerate(doc.value.value.splitlines()):
                    yield doc.lineno + i, line


def prose_of(path: Path):
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".py":
        yield from python_prose(text)
    else:
        yield from enumerate(text.splitlines(), 1)


def scanned() -> list:
    """The files whose prose is checked."""
    groups = [ROOT.glob("docs/*.md"), [ROOT / "README.md", ROOT / "Snakefile", ROOT / "workflow" / "Snakefile"],
              (ROOT / "src").rglob("*.py"), ROOT.glob("workflow/rules/*.smk"), ROOT.glob("workflow/scripts/*.py"),
              ROOT.glob("workflow/schemas/*.yaml"), ROOT.glob("config/*.yaml")]
    return sorted({p for g in groups for p in g if p.is_file()})


def stale(path: Path) -> list:
    return [f"{path.relative_to(ROOT)}:{i}: {token}" for i, text in prose_of(path)
            for token in named_paths(text) if not exists(token, path)]


def test_the_scanner_finds_and_misses(tmp_path):
    """The scanner itself: a bare rule file, a path from the root, a tail, a relative path,
    placeholders and outputs skipped, string literals of Python code not prose."""
    assert list(named_paths("rules/face.smk: x; see `docs/api.md`, ../scripts/beta_job.py. a.smk")) == [
        "rules/face.smk", "docs/api.md", "../scripts/beta_job.py", "a.smk"]
    assert list(named_paths("DIR/levels.yaml results/x/y.py path/to/file.py {model}/a.py la.py")) == []
    rules = ROOT / "workflow" / "rules" / "models.smk"
    assert exists("../scripts/model_job.py", rules) and not exists("../scripts/no_such_job.py", rules)
    assert exists("rules/models.smk", rules) and exists("plans/membranes3d.py", rules)
    assert not exists("rules/face_studies.smk", rules)
    source = '"""Doc (rules/gone.smk)."""\nX = "rules/data.smk"  # rules/comment.smk\n'
    assert sorted(t for _, text in python_prose(source) for t in named_paths(text)) == [
        "rules/comment.smk", "rules/gone.smk"]


def test_the_scan_covers_docs_sources_and_workflow():
    names = {p.relative_to(ROOT).as_posix() for p in scanned()}
    for expected in ("README.md", "docs/package.md", "src/infsup_contact/table_schemas.py",
                     "workflow/rules/models.smk", "workflow/scripts/model_job.py", "config/config.yaml"):
        assert expected in names


@pytest.mark.parametrize("group", ["docs", "src", "workflow", "config"])
def test_every_path_named_in_prose_exists(group):
    paths = [p for p in scanned() if p.relative_to(ROOT).parts[0] == group
             or (group == "docs" and p.name in ("README.md", "Snakefile") and p.parent == ROOT)]
    missing = [line for p in paths for line in stale(p)]
    assert not missing, f"{len(missing)} paths named in prose do not exist:\n" + "\n".join(missing)
