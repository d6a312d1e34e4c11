"""No case id is special-cased outside the registry (issue 27, item 4): the report package, the
workflow rules and the workflow scripts name no space id in code. Groups (stable/unstable, the
paper's cases) come from registry properties, figure choices from the config (key figures).
Ids may appear in comments and docstrings only."""
import io
import re
import tokenize
from pathlib import Path

from infsup_contact.discretization.spaces.registry import SPACES

ROOT = Path(__file__).resolve().parents[3]
FOLDERS = ("src/infsup_contact/report", "workflow/rules", "workflow/scripts")
IDS = sorted({*SPACES, "P0-2h"}, key=len, reverse=True)  # the built-in ids and the example user space
ID_RE = re.compile(r"(?<![\w.-])(" + "|".join(re.escape(i) for i in IDS) + r")(?![\w.-])")
SKIP = {tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.COMMENT}


def code_strings(text: str):
    """(line, literal) of every string literal of ``text`` that is not a docstring (a string
    standing alone as a statement); comments are not string tokens."""
    toks = [t for t in tokenize.generate_tokens(io.StringIO(text).readline)]
    for i, tok in enumerate(toks):
        if tok.type != tokenize.STRING:
            continue
        prev = next((t for t in reversed(toks[:i]) if t.type not in (tokenize.NL, tokenize.COMMENT)), None)
        nxt = next((t for t in toks[i + 1:] if t.type != tokenize.COMMENT), None)
        alone = (prev is None or prev.type in (tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT)) and \
            (nxt is None or nxt.type in (tokenize.NEWLINE, tokenize.NL, tokenize.ENDMARKER))
        if not alone:
            yield tok.start[0], tok.string


STYLE_TABLE = ROOT / "src/infsup_contact/report/case_styles.py"
"""The one table keyed by id on purpose: how each built-in space is drawn (data, no branch)."""


def files():
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*")):
            if (path.suffix in (".py", ".smk") or path.name == "Snakefile") and path != STYLE_TABLE:
                yield path


def test_the_style_table_holds_data_only():
    """case_styles.py is exempt from the scan above, so it must hold assignments only (no def,
    no if): a colour per id cannot become a special case of the id."""
    import ast

    tree = ast.parse(STYLE_TABLE.read_text())
    assert all(isinstance(node, (ast.Expr, ast.Assign, ast.ImportFrom, ast.Import)) for node in tree.body)
    assert not any(isinstance(node, (ast.If, ast.IfExp, ast.Compare, ast.FunctionDef, ast.Lambda))
                   for node in ast.walk(tree))


def test_scanner_sees_code_and_skips_docs():
    text = '"""T3 in a docstring."""\nx = 1  # T3 in a comment\ngroups = ("T3", "R5.4")\n' \
           'def f():\n    """DUAL here is fine."""\n    return case != "DUAL-ALL"\n'
    hits = sorted({line for line, src in code_strings(text) if ID_RE.search(src)})
    assert hits == [3, 6]


def test_no_case_id_outside_the_registry():
    found = []
    for path in files():
        text = path.read_text()
        for line, src in code_strings(text):
            if ID_RE.search(src):
                found.append(f"{path.relative_to(ROOT)}:{line}: {src}")
    assert list(files()), "no files scanned"
    assert not found, "case ids special-cased outside the registry:\n" + "\n".join(dict.fromkeys(found))


# ------------------------------------------------------------------ the config's figure choices

import copy  # noqa: E402

import pytest  # noqa: E402
import yaml  # noqa: E402

from infsup_contact.config.checks import ConfigError, check_config  # noqa: E402

SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


@pytest.mark.parametrize("name", ["config.yaml", "ci.yaml"])
def test_elastic_stage_runs_the_configs_spaces(name):
    """One list of spaces for the DAG (infsup.cases): both configs list every registered space
    of the segment (the 2D DAG's; the face spaces of the 3D models are not its) and their user
    space, so the elastic stage runs what it ran when it took every registered space (the
    tables stay as they were)."""
    from infsup_contact.discretization.spaces.registry import common_ids
    from infsup_contact.discretization.spaces.user_spaces import load_user_space

    cfg = yaml.safe_load((ROOT / "config" / name).read_text())
    users = [load_user_space(ref).id for ref in cfg["spaces"]]
    builtin = [c for c in common_ids() if c not in users]
    assert list(cfg["infsup"]["cases"]) == [*builtin, *users]


@pytest.mark.parametrize("path, value, needle", [
    (("contact_solutions", "cases"), ["T4", "NOPE"], "config key figures.contact_solutions.cases[1]"),
    (("dual", "cases"), ["T3", "NOPE"], "config key figures.dual.cases[1]"),
    (("elastic_profiles", "pairs"), [["NOPE", 1]], "config key figures.elastic_profiles.pairs[0]"),
    (("nu_slope_cases",), ["NOPE"], "config key figures.nu_slope_cases[0]"),
    (("contact_solutions", "k"), 1, "config key figures.contact_solutions.cases[0]"),  # T4 needs k >= 2
    (("dual", "scene"), "nowhere", "config key figures.dual.scene"),
])
def test_figure_choices_are_checked(path, value, needle):
    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config" / "ci.yaml").read_text()))
    node = cfg["figures"]
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = str(err.value)
    assert "\n" not in text and text.startswith(needle), text


# ------------------------------------------------------------------ scene and model ids

import ast  # noqa: E402

from infsup_contact.models import MODELS  # noqa: E402
from infsup_contact.study.contact.registry import scene_ids  # noqa: E402

REGISTRIES = ("src/infsup_contact/study/contact/registry.py", "src/infsup_contact/models")
"""Where scene and model ids are declared: the scene registry, and the model registry with its
models (a model names itself)."""
NAMED = sorted({*scene_ids(), *MODELS}, key=len, reverse=True)
SMK_BRANCH = re.compile(r"""(?:[=!]=\s*|\bin\s+)["'](%s)["']|["'](%s)["']\s*[=!]=|\w+\s*=\s*["'](%s)["']\s*,"""
                        % (("|".join(map(re.escape, NAMED)),) * 3))


def special_cased(tree) -> list:
    """(line, id) where a scene or model id is compared with (==, !=, in) or is a parameter's
    default: how a consumer branches on an id instead of asking a registry."""
    hits = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            hits += [(o.lineno, o.value) for o in operands
                     if isinstance(o, ast.Constant) and o.value in NAMED]
            hits += [(e.lineno, e.value) for o in operands if isinstance(o, (ast.Tuple, ast.List, ast.Set))
                     for e in o.elts if isinstance(e, ast.Constant) and e.value in NAMED]
        elif isinstance(node, (ast.FunctionDef, ast.Lambda)):
            defaults = [*node.args.defaults, *(d for d in node.args.kw_defaults if d is not None)]
            hits += [(d.lineno, d.value) for d in defaults if isinstance(d, ast.Constant) and d.value in NAMED]
    return hits


def test_branch_scanner_sees_comparisons_and_defaults():
    text = ('if scene == "manufactured":\n    pass\nok = kind in ("membranes", "x")\n'
            'def f(s="hertz"):\n    return cfg["elastic"]\nlabel = "patch"\n')
    assert sorted(special_cased(ast.parse(text))) == [(1, "manufactured"), (3, "membranes"), (4, "hertz")]
    assert SMK_BRANCH.search('    if kind != "membranes":') and SMK_BRANCH.search('        scene="manufactured",')
    assert not SMK_BRANCH.search('    ec = config["elastic"]')


def test_no_scene_or_model_id_special_cased_outside_its_registry():
    found = []
    for folder in ("src/infsup_contact", "workflow"):
        for path in sorted((ROOT / folder).rglob("*")):
            rel = str(path.relative_to(ROOT))
            if rel.startswith(REGISTRIES) or path.suffix not in (".py", ".smk"):
                continue
            text = path.read_text()
            if path.suffix == ".py":
                found += [f"{rel}:{line}: {value!r}" for line, value in special_cased(ast.parse(text))]
            else:
                found += [f"{rel}:{i}: {line.strip()}" for i, line in enumerate(text.splitlines(), 1)
                          if SMK_BRANCH.search(line.split("#")[0])]
    assert not found, "scene or model ids special-cased outside their registries:\n" + "\n".join(found)


def test_config_scene_kinds_are_the_registrys_data_scenes():
    """The schema's enum of contact.scenes.*.kind lists exactly the registered scenes with data."""
    from infsup_contact.study.contact.registry import data_scene_ids

    schema = yaml.safe_load(SCHEMA.read_text())
    kind = schema["properties"]["contact"]["properties"]["scenes"]["additionalProperties"]["properties"]["kind"]
    assert sorted(kind["enum"]) == sorted(data_scene_ids())


@pytest.mark.parametrize("name, allowed", [("membranes", "manufactured"), ("nowhere", "manufactured")])
def test_primary_scene_must_have_an_exact_solution(name, allowed):
    cfg = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
    cfg["contact"]["primary_scene"] = name
    with pytest.raises(ConfigError, match=rf"contact\.primary_scene.*{allowed}"):
        check_config(cfg, SCHEMA)
