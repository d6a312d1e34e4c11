"""The documentation's shape: a short README linking every docs/ page, relative links that
resolve, and docstrings without issue numbers (history lives in CHANGELOG.md and git)."""
import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted((ROOT / "docs").glob("*.md"))


def test_the_readme_is_short_and_links_every_docs_page():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.splitlines()) <= 200
    assert "make test" in readme and "make reproduce-all" in readme
    for page in PAGES:
        assert f"](docs/{page.name})" in readme, f"README.md does not link docs/{page.name}"


@pytest.mark.parametrize("page", [ROOT / "README.md", ROOT / "CHANGELOG.md", *PAGES], ids=lambda p: p.name)
def test_relative_links_resolve(page):
    for link in re.findall(r"\]\(([^)#\s]+)", page.read_text(encoding="utf-8")):
        if not re.match(r"[a-z]+:", link):
            assert (page.parent / link).exists(), f"{page.name}: broken link {link}"


def docstrings(path: Path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            text = ast.get_docstring(node, clean=False)
            if text:
                yield node, text
        # attribute docstrings: a string expression right after an assignment
        body = getattr(node, "body", None)
        body = body if isinstance(body, list) else []
        for before, after in zip(body[:-1], body[1:]):
            if isinstance(before, (ast.Assign, ast.AnnAssign)) and isinstance(after, ast.Expr) \
                    and isinstance(after.value, ast.Constant) and isinstance(after.value.value, str):
                yield after, after.value.value


def test_no_docstring_cites_an_issue():
    found = [f"{path.relative_to(ROOT)}:{getattr(node, 'lineno', 1)}"
             for path in sorted((ROOT / "src").rglob("*.py")) for node, text in docstrings(path)
             if re.search(r"(?i)\bissues? #?\d+|\(#\d+\)", text)]
    assert not found, f"docstrings citing an issue number: {found}"


@pytest.mark.parametrize("page", [ROOT / "README.md", *PAGES], ids=lambda p: p.name)
def test_no_text_is_pasted_twice(page):
    """A phrase repeated back to back ("exact coupling" + "exact coupling") is an edit gone wrong."""
    text = " ".join(re.sub(r"```.*?```", " ", page.read_text(encoding="utf-8"), flags=re.S).split())
    doubled = [m.group(1) for m in re.finditer(r"(.{16,200}?)\1", text)
               if re.search(r"[A-Za-z]{3}", m.group(1))]
    assert not doubled, f"{page.name}: pasted twice: {doubled}"
