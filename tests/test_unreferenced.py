"""No module-level function or constant of ``src/`` that nothing names: a leftover is deleted, not
kept in case.

A definition is a module-level ``def`` or an assignment to an UPPER_CASE name (``DELTA = 1e-2``).
It is referenced when its name occurs anywhere else in the repository's code and prose — the
package, the tests (but this one), the workflow (rule files, scripts), the examples, the docs — as an identifier
or inside a string (``"study.contact.runs:membrane_rows"``, the registry's way of naming a
function; a Snakefile's ``script:``). Words are counted, not resolved: a name used anywhere
counts for every definition of it, so the check never calls a used name dead (it may miss a
dead one that shares a live one's name).
"""
from __future__ import annotations

import ast
import re
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "infsup_contact"
CONSTANT = re.compile(r"_?[A-Z][A-Z0-9_]*$")
WORD = re.compile(r"[A-Za-z_]\w*")


def corpus(root: Path = ROOT) -> list:
    """The files whose words can reference a definition of the package."""
    groups = [root.glob("src/**/*.py"), root.glob("tests/**/*.py"), root.glob("workflow/**/*.smk"),
              root.glob("workflow/**/*.py"), root.glob("examples/**/*.py"), root.glob("docs/*.md"),
              [root / "Snakefile", root / "workflow" / "Snakefile", root / "README.md"]]
    return sorted({p for g in groups for p in g if p.is_file() and p != Path(__file__).resolve()})


def definitions(source: str):
    """(line, name) of the module-level functions and UPPER_CASE constants of ``source``."""
    for node in ast.parse(source).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node.lineno, node.name
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                for n in ast.walk(target):
                    if isinstance(n, ast.Name) and CONSTANT.match(n.id) and not n.id.startswith("__"):
                        yield node.lineno, n.id


def unreferenced(modules, texts) -> list:
    """``path:line: name`` of each definition of ``modules`` whose name occurs once in ``texts``
    (its own definition)."""
    words = Counter(w for text in texts for w in WORD.findall(text))
    return [f"{path}:{line}: {name}" for path in modules
            for line, name in definitions(path.read_text(encoding="utf-8")) if words[name] < 2]


def test_the_check_sees_functions_constants_and_string_references(tmp_path):
    module = tmp_path / "m.py"
    module.write_text('X = 1\n_Y, Z = 2, 3\nlower = 4\n\ndef f():\n    return X\n\ndef g():\n    """f."""\n'
                      '\nclass C:\n    W = 5\n\n    def h(self):\n        pass\n')
    other = 'REGISTRY = "m:unused_elsewhere"\n'
    found = unreferenced([module], [module.read_text(), other])
    assert found == [f"{module}:2: _Y", f"{module}:2: Z", f"{module}:8: g"]  # f named in g's docstring; C's members skipped
    assert unreferenced([module], [module.read_text(), "g, _Y and Z in a rule file"]) == []


def test_no_unreferenced_function_or_constant_in_src():
    modules = sorted(SRC.rglob("*.py"))
    assert len(modules) > 100  # the package is where this test looks
    dead = unreferenced(modules, [p.read_text(encoding="utf-8") for p in corpus()])
    assert not dead, (f"{len(dead)} module-level definitions nothing names (delete them):\n"
                      + "\n".join(str(d).replace(str(ROOT) + "/", "") for d in dead))
