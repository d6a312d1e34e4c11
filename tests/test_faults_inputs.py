"""Fault injection, inputs (issue 26): each fault gets ONE line naming the thing, or a documented
acceptance.

Classes: perturbed meshes (α beyond the bound, inverted or missing elements), empty
multiplier spaces (every case/k/N the registry's dimension counts make empty, through the
library and every subcommand), config N lists with N = 1, faulty user spaces, YAML 1.1 quirks
and scene names. In-process (the library, ``cli.main``), except one Snakemake run that shows
the strict YAML reading is hooked in front of the workflow.
"""
import copy
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from infsup_contact.cli import main as cli_main
from infsup_contact.config.checks import ConfigError, check_config, key_path
from infsup_contact.config.meshes import mesh_uses
from infsup_contact.config.strict_yaml import check_config_file
from infsup_contact.discretization.segment import meshes
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.spaces.user_spaces import load_user_space
from infsup_contact.errors import InputError
from infsup_contact.discretization.segment.interface import SEGMENT

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
CI_CONFIG = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())


def one_line(text) -> str:
    text = str(text)
    assert "\n" not in text.strip() and "Traceback" not in text, text
    return text


@pytest.fixture(autouse=True)
def forget_user_spaces():
    """Each test registers what it loads; the registry is left as the other tests expect it."""
    from infsup_contact.discretization.spaces import user_spaces

    before = set(SPACES)
    yield
    user_spaces.forget_since(before)


def run_cli(capsys, *argv) -> tuple[int, str]:
    """``infsup-contact ARGV`` in-process: (exit code, stderr)."""
    code = cli_main(list(argv))
    return code, capsys.readouterr().err.strip()


# ------------------------------------------------------------------ 1. perturbed meshes

BEYOND = [0.2 + 1e-9, 0.25, 0.3, 0.45, 0.5, -0.01, float("nan"), float("inf")]


def test_the_builders_defaults_are_none_and_pass():
    """A request that leaves α and the seed to the mesh builder (None) is checked with them:
    nothing to refuse; a wrong seed or α beside a None is still refused, naming its key."""
    meshes.check_perturbation(None, None)
    for alpha, seed, key in ((None, -1, "seed"), (None, True, "seed"), (0.3, None, "alpha"), ("x", None, "alpha")):
        with pytest.raises(InputError) as err:
            meshes.check_perturbation(alpha, seed)
        assert err.value.key == key


@pytest.mark.parametrize("alpha", BEYOND)
def test_alpha_beyond_the_bound_is_refused(alpha, capsys):
    with pytest.raises(InputError) as err:
        meshes.check_perturbation(alpha, 0)
    assert err.value.key == "alpha" and f"[0, {meshes.ALPHA_MAX:g}]" in one_line(err.value)
    code, err_line = run_cli(capsys, "beta", "--case", "T3", "--k", "1", "--family", "perturbed",
                             "--N1", "4", "--N2", "4", "--alpha", str(alpha), "--dry-run")
    assert code == 2 and one_line(err_line).startswith("infsup-contact: error: invalid --alpha")
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["infsup"]["alpha"] = alpha
    with pytest.raises(ConfigError) as cerr:
        check_config(cfg, SCHEMA)
    assert one_line(cerr.value).startswith("config key infsup.alpha")


@pytest.mark.parametrize("alpha", [0.1, 0.2, 0.3])
def test_perturbation_bound_holds_for_random_draws(alpha):
    """The worst case over every displacement (corners of the box, where the multi-affine
    signed area is extreme) bounds every seed's triangles; it is 1 − 4α."""
    bound, angle = meshes.perturbation_bounds(alpha)
    assert bound == pytest.approx(1 - 4 * alpha, abs=1e-12)
    assert (angle > 0) == (alpha <= meshes.ALPHA_MAX)
    for n in (4, 7, 16):
        points, triangles = meshes.structured_arrays(n, 1)
        ratios = [meshes.signed_areas(meshes.perturb(points, n, 1, alpha, s), triangles).min() / (0.5 / n**2)
                  for s in range(20)]
        assert min(ratios) >= bound - 1e-12


def test_alpha_at_the_bound_builds_checked_meshes():
    """Documented acceptance: α = ALPHA_MAX is allowed and every seed's mesh passes the check."""
    for seed in range(3):
        m1, m2 = meshes.mesh_pair("perturbed", 8, 8, alpha=meshes.ALPHA_MAX, seed=seed)
        assert meshes.mesh_quality(m1)["min_angle"] >= meshes.perturbation_bounds(meshes.ALPHA_MAX)[1]


def _flip_one(arrays):
    def flipped(n, side):
        points, triangles = arrays(n, side)
        triangles = triangles.copy()
        triangles[0, [1, 2]] = triangles[0, [2, 1]]
        return points, triangles
    return flipped


def _drop_one(arrays):
    def dropped(n, side):
        points, triangles = arrays(n, side)
        return points, triangles[1:]
    return dropped


MESH_FAULTS = {
    # name: (monkeypatch(meshes) → kwargs of subdomain_mesh, needles)
    "inverted-by-alpha-0.45": (lambda mp: mp.setattr(meshes, "ALPHA_RANGE", (0.0, 0.5)),
                               dict(family="perturbed", n=16, alpha=0.45, seed=0),
                               ["perturbed", "N = 16", "seed 0", "alpha 0.45", "inverted"]),
    "one-triangle-flipped": (lambda mp: mp.setattr(meshes, "structured_arrays", _flip_one(meshes.structured_arrays)),
                             dict(family="structured", n=4), ["structured", "N = 4", "inverted"]),
    "one-triangle-missing": (lambda mp: mp.setattr(meshes, "structured_arrays", _drop_one(meshes.structured_arrays)),
                             dict(family="perturbed", n=5, alpha=0.1, seed=2),
                             ["perturbed", "N = 5", "seed 2", "alpha 0.1", "sum to"]),
}


@pytest.mark.parametrize("name", list(MESH_FAULTS))
def test_bad_mesh_is_detected_naming_family_n_seed_alpha(name, monkeypatch):
    patch, kwargs, needles = MESH_FAULTS[name]
    patch(monkeypatch)
    family, n = kwargs.pop("family"), kwargs.pop("n")
    with pytest.raises(InputError) as err:
        meshes.subdomain_mesh(family, n, 1, **kwargs)
    for needle in needles:
        assert needle in one_line(err.value), err.value


# ------------------------------------------------------------------ 2. empty spaces

def empty_combinations(n_max: int = 3) -> list:
    """(case, k, N) with dim M_h = 0 by the registry's own dimension counts (the paper's), for
    the spaces of the segment (the commands below run 2D models; the face spaces' refusal is
    tested in test_face_dual_beta.py)."""
    return [(c, k, n) for c, spec in SPACES.items() if spec.dimension is not None and spec.defined_on(1)
            for k in range(1, 5) if spec.valid_for(k) for n in range(1, n_max + 1) if spec.dimension(k, n) == 0]


EMPTY = empty_combinations()


def test_the_registry_has_empty_combinations():
    """The counts make T3 and DUAL empty for k = 1 on one interval (n k − 1 = 0)."""
    assert {("T3", 1, 1), ("DUAL", 1, 1)} <= set(EMPTY)


@pytest.mark.parametrize("case, k, n", EMPTY)
def test_empty_space_is_refused_before_any_computation(case, k, n, capsys, monkeypatch):
    from infsup_contact.solvers.request import BetaRequest

    def no_mesh(*a, **kw):  # "before any computation": no mesh may be built
        raise AssertionError("a mesh was built for an empty space")
    monkeypatch.setattr(meshes, "subdomain_mesh", no_mesh)
    with pytest.raises(InputError) as err:
        BetaRequest("structured", k, n, n, (case,), norms=("H",))
    text = one_line(err.value)
    assert f"case {case}" in text and f"k = {k}" in text and f"N = {n}" in text
    with pytest.raises(InputError):  # the backstop every consumer of the registry goes through
        registry.case_space(case, k, np.linspace(0.0, 1.0, n + 1), SEGMENT)
    argvs = {
        "beta": ["beta", "--case", case, "--k", str(k), "--N1", str(n), "--N2", str(n)],
        "verdict": ["verdict", "--case", case, "--k", str(k), "--N", str(n), "8", "16"],
        "contact": ["contact", "--case", case, "--k", str(k), "--N1", str(n), "--N2", str(n),
                    "--scene", "manufactured"],
        "patch": ["contact", "--case", case, "--k", str(k), "--N1", str(n + 1), "--N2", str(n),
                  "--scene", "patch", "--model", "elastic"],
        "bench": ["bench", "--what", "beta", "--N", str(n), "--k", str(k)],
    }
    for name, argv in argvs.items():
        code, line = run_cli(capsys, *argv)
        assert code == 2, (name, line)
        assert f"case " in one_line(line) and f"k = {k}" in line and "dim M_h = 0" in line, (name, line)


@pytest.mark.parametrize("argv, refused", [
    (["--case", "DUAL", "--k", "1", "--N1", "3", "--N2", "1", "--multiplier-mesh", "omega2"], True),
    (["--case", "DUAL", "--k", "1", "--N1", "1", "--N2", "3", "--multiplier-mesh", "omega1"], True),
    # documented acceptance: the union of 3 and 1 segments has 3 intervals, DUAL has 2 functions
    (["--case", "DUAL", "--k", "1", "--N1", "3", "--N2", "1", "--multiplier-mesh", "union"], False),
    (["--case", "T3", "--k", "2", "--N1", "1", "--N2", "1"], False),   # dim = 2·1 − 1 = 1
])
def test_empty_multiplier_mesh_of_a_pair(argv, refused, capsys):
    code, line = run_cli(capsys, "beta", *argv, "--dry-run")
    if refused:
        assert code == 2 and "dim M_h = 0" in one_line(line) and "N1 = " in line, line
    else:
        assert code == 0, line


def test_multiplier_mesh_with_no_interval():
    with pytest.raises(InputError) as err:
        registry.case_space("T3", 2, np.array([0.0]), SEGMENT)
    assert "at least one interval" in one_line(err.value) and "case T3" in str(err.value)


# ------------------------------------------------------------------ 3. config N lists with N = 1

def _n1(cfg, path):
    """Put N = 1 (a pair (2, 1): Ω2's trace, the multiplier mesh, one interval) first in the list."""
    node = cfg
    for key in path[:-1]:
        node = node[key]
    value = node[path[-1]]
    if isinstance(value, list):
        value[0] = [2, 1] if isinstance(value[0], list) else 1
    else:
        node[path[-1]] = 1


N_LISTS = {
    # key path: outcome of N = 1 — "empty" (refused: a space run there has dim M_h = 0),
    # "schema" (the schema's minimum already refuses it), "accepted" (documented: every space
    # run there is non-empty on one interval)
    ("infsup", "N"): "empty",
    ("infsup", "nonmatching"): "empty",
    ("infsup", "nonmatching_families", "plus1"): "empty",
    ("infsup", "nonmatching_families", "sqrt2"): "schema",  # round(√2·1) = 1: no pair; N2 >= 2
    ("contact", "N"): "empty",
    ("contact", "scenes", "membranes", "N"): "empty",
    ("studies", "elastic", "N"): "empty",
    ("studies", "elastic", "nonmatching"): "empty",
    ("studies", "elastic", "patch_pairs"): "empty",
    ("studies", "elastic", "bench_N"): "empty",
    ("studies", "elastic", "hertz", "N"): "empty",
    ("studies", "elastic", "hertz", "modeling_N"): "accepted",  # T3 with k = 2: dim = 2·1 − 1 = 1
    ("benchmarks", "beta_N"): "empty",
    ("benchmarks", "contact_N"): "empty",
    ("claims", "rem55_N"): "empty",
    ("figures", "contact_solutions", "N"): "accepted",  # k = 2: T4 dim 1, R5.4 dim 2
    ("figures", "dual", "N"): "accepted",  # k = 2: T3 and DUAL dim 2·1 − 1 = 1
    ("figures", "elastic_profiles", "N"): "empty",  # T3 with k = 1: dim 0
}


def test_every_n_list_is_covered():
    """Every mesh key the config checks (config.meshes.mesh_uses) is mutated here."""
    keys = {key.split("[")[0] for key, *_ in mesh_uses(CI_CONFIG, with_cases=False)}
    assert keys <= {key_path(p) for p in N_LISTS}, keys - {key_path(p) for p in N_LISTS}


@pytest.mark.parametrize("path", list(N_LISTS), ids=[key_path(p) for p in N_LISTS])
def test_n_equal_one_in_every_n_list(path):
    cfg = copy.deepcopy(CI_CONFIG)
    _n1(cfg, path)
    if N_LISTS[path] == "accepted":
        check_config(cfg, SCHEMA)
        return
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = one_line(err.value)
    assert text.startswith(f"config key {key_path(path)}"), text
    if N_LISTS[path] == "empty":
        assert "dim M_h = 0" in text and "case " in text and "k = " in text, text
    else:
        assert "minimum" in text, text


# ------------------------------------------------------------------ 4. user spaces

HEADER = """
import numpy as np
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.spaces.spec import SpaceSpec

def good_build(k, x):
    return make_space(x, k, True, True)
"""
USER_FAULTS = {
    # name: (module body, function, needles)
    "space-raises": ("def space():\n    raise RuntimeError('boom')\n", "space", ["space()", "RuntimeError", "boom"]),
    "systemexit-at-import": ("raise SystemExit(3)\n", "space", ["import of", "SystemExit", "3"]),
    "systemexit-in-space": ("def space():\n    raise SystemExit(3)\n", "space", ["space()", "SystemExit"]),
    "baseexception-in-build": ("class Boom(BaseException):\n    pass\n\ndef b(k, x):\n    raise Boom('deep')\n\n"
                               "def space():\n    return SpaceSpec('U-boom', 'user', '', b, lambda k: k)\n",
                               "space", ["build(k=1", "Boom", "deep"]),
    "dimension-raises": ("def space():\n    return SpaceSpec('U-dim', 'user', '', good_build, lambda k: k, "
                         "dimension=lambda k, n: 1 / 0)\n", "space", ["dimension(", "ZeroDivisionError"]),
    "unknown-keyword": ("def space():\n    return SpaceSpec('U-kw', 'user', '', good_build, lambda k: k, "
                        "colour='red')\n", "space", ["unexpected keyword", "colour", "SpaceSpec takes"]),
    "non-string-id": ("def space():\n    return SpaceSpec(42, 'user', '', good_build, lambda k: k)\n", "space",
                      ["space id", "42", "letters"]),
    "the-build-function": ("def space():\n    return SpaceSpec('U-ok', 'user', '', good_build, lambda k: k)\n",
                           "good_build", ["good_build", "build function", "(k, x)"]),
    "not-a-spacespec": ("def space():\n    return {'id': 'U'}\n", "space", ["SpaceSpec", "dict"]),
    "ignores-partition": ("def b(k, x):\n    return make_space(np.linspace(0, 1, 6), k, True, True)\n\n"
                          "def space():\n    return SpaceSpec('U-fixed', 'user', '', b, lambda k: k)\n", "space",
                          ["U-fixed", "partition it is given"]),
    "wrong-degree": ("def space():\n    return SpaceSpec('U-deg', 'user', '', good_build, lambda k: 0)\n", "space",
                     ["U-deg", "local degree 0"]),
    "missing-function": ("x = 1\n", "space", ["a function space"]),
}
BAD_IDS = ["", "x{k}", "a b", "T_3", "-x", "3T", "a" * 33, "dollar$", "back\\slash"]
GOOD_IDS = ["My-space.2", "P0-2h", "x"]


def write_module(tmp_path, name, body) -> Path:
    path = tmp_path / f"{name.replace('-', '_')}.py"
    path.write_text(HEADER + body)
    return path


@pytest.mark.parametrize("name", list(USER_FAULTS))
def test_faulty_user_space_one_line_naming_file_function_exception(tmp_path, name, capsys):
    body, func, needles = USER_FAULTS[name]
    path = write_module(tmp_path, name, body)
    ref = f"{path}:{func}"
    with pytest.raises(InputError) as err:
        load_user_space(ref)
    text = one_line(err.value)
    assert str(path) in text or "U-" in text, text
    for needle in needles:
        assert needle in text, (needle, text)
    code, line = run_cli(capsys, "beta", "--space", ref, "--k", "2", "--N1", "4", "--N2", "4", "--dry-run")
    assert code == 2 and one_line(line).startswith("infsup-contact: error:"), line
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["spaces"] = [*cfg.get("spaces", []), ref]
    with pytest.raises(ConfigError) as cerr:
        check_config(cfg, SCHEMA)
    assert one_line(cerr.value).startswith(f"config key spaces[{len(cfg['spaces']) - 1}]: ")


@pytest.mark.parametrize("space_id", BAD_IDS + GOOD_IDS)
def test_space_ids(tmp_path, space_id):
    path = write_module(tmp_path, "ids", f"def space():\n    return SpaceSpec({space_id!r}, 'u', '', good_build, "
                                           "lambda k: k)\n")
    if space_id in GOOD_IDS and space_id not in SPACES:
        assert load_user_space(f"{path}:space").id == space_id
        return
    with pytest.raises(InputError) as err:
        load_user_space(f"{path}:space")
    assert "letters, digits" in one_line(err.value) or "already registered" in str(err.value)


PARTITION_FAULTS = {
    # a space right on the check partition (N = 5) and wrong elsewhere
    "ignores-partition-off-5": ("def b(k, x):\n    y = x if len(x) == 6 else np.linspace(0, 1, 6)\n"
                                "    return make_space(y, k, True, True)\n",
                                "dimension=lambda k, n: 5 * k - 1", "partition it is given"),
    "dimension-wrong-off-5": ("b = good_build\n", "dimension=lambda k, n: n * k - 1 if n == 5 else 7", "dimension 7"),
    "empty-build-fails-on-1": ("def b(k, x):\n    assert len(x) > 2, 'needs two intervals'\n"
                               "    return make_space(x, k, True, True)\n", "dimension=None", "needs two intervals"),
}


@pytest.mark.parametrize("name", list(PARTITION_FAULTS))
def test_space_checked_on_every_partition_of_the_run(tmp_path, name, capsys):
    body, dim, needle = PARTITION_FAULTS[name]
    n = 1 if "on-1" in name else 8
    path = write_module(tmp_path, name, body + f"\ndef space():\n    return SpaceSpec('U-{name}', 'u', '', b, "
                                                f"lambda k: k, {dim})\n")
    ref = f"{path}:space"
    code, line = run_cli(capsys, "beta", "--space", ref, "--k", "2", "--N1", str(n), "--N2", str(n), "--dry-run")
    assert code == 2 and needle in one_line(line) and f"N = {n}" in line, line
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["spaces"] = [ref]
    cfg["infsup"]["N"] = [n, *[m for m in cfg["infsup"]["N"] if m != n]]
    with pytest.raises(ConfigError) as cerr:
        check_config(cfg, SCHEMA)
    assert one_line(cerr.value).startswith("config key spaces[0]: ") and needle in str(cerr.value)


def test_every_later_build_is_guarded(tmp_path):
    """A space registered after its checks still cannot compute on a partition it ignores: the
    registered build checks each result (jobs build on partitions no check saw)."""
    body, dim, needle = PARTITION_FAULTS["ignores-partition-off-5"]
    path = write_module(tmp_path, "later", body + f"\ndef space():\n    return SpaceSpec('U-later', 'u', '', b, "
                                                  f"lambda k: k, {dim})\n")
    spec = load_user_space(f"{path}:space")
    with pytest.raises(InputError) as err:
        registry.case_space(spec.id, 1, np.linspace(0.0, 1.0, 8), SEGMENT)
    assert needle in one_line(err.value)


def test_keyboard_interrupt_is_not_swallowed(tmp_path):
    """Documented acceptance: Ctrl-C in a user's code stays Ctrl-C (the guard lets it through)."""
    path = write_module(tmp_path, "ctrlc", "def space():\n    raise KeyboardInterrupt\n")
    with pytest.raises(KeyboardInterrupt):
        load_user_space(f"{path}:space")


# ------------------------------------------------------------------ 5. YAML and scene names

YAML_FAULTS = {
    "duplicate-top": ("spaces: []\nspaces: []\n", "spaces", "given twice"),
    "duplicate-nested": ("infsup:\n  alpha: 0.2\n  alpha: 0.1\n", "infsup.alpha", "given twice"),
    "duplicate-in-list": ("s:\n  - {a: 1, a: 2}\n", "s[0].a", "given twice"),
    "octal": ("infsup:\n  N: [004, 010]\n", "infsup.N[0]", "octal number 4"),
    "octal-second": ("infsup:\n  N: [4, 010]\n", "infsup.N[1]", "octal number 8"),
    "zero-padded-9": ("infsup:\n  N: [09]\n", "infsup.N[0]", "the string '09'"),
    "1e3": ("claims:\n  beta_floor: 1e3\n", "claims.beta_floor", "signed exponent"),
    "1.0e3": ("claims:\n  beta_floor: 1.0e3\n", "claims.beta_floor", "signed exponent"),
    "-1e-3": ("x: -1e-3\n", "x", "read as a string"),
    "json-duplicate": ('{"a": 1, "a": 2}', "a", "given twice"),
    # a plain list past the limit: its size is the problem, not aliases it does not have
    "long-list": ("x: &x 1\ny: *x\nb: [" + "0, " * 100_001 + "]\n", "b", "a list of 100,001 items"),
}
YAML_ACCEPTED = {
    "quoted-1e3": "a: '1e3'\n",
    "signed-exponent": "a: 1.0e+3\n",
    "plain-zero": "a: 0\nb: [0, 0.5]\n",
    "json-1e3": '{"a": 1e3}',
}


@pytest.mark.parametrize("name", list(YAML_FAULTS))
def test_yaml_quirk_is_refused(tmp_path, name):
    text, key, needle = YAML_FAULTS[name]
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        check_config_file(path)
    assert one_line(err.value).startswith(f"config key {key}:") and needle in str(err.value), err.value


@pytest.mark.parametrize("name", list(YAML_ACCEPTED) + ["config.yaml", "ci.yaml"])
def test_yaml_accepted(tmp_path, name):
    path = ROOT / "config" / name if name.endswith(".yaml") else tmp_path / "c.yaml"
    if not name.endswith(".yaml"):
        path.write_text(YAML_ACCEPTED[name])
    check_config_file(path)


@pytest.mark.parametrize("scene", ["", "x{k}", "a b", "9lives", "a/b"])
def test_bad_scene_name(scene):
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["contact"]["scenes"][scene] = {"kind": "manufactured", "p": 3.0, "q": 3.0}
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith("config key contact.scenes:") and repr(scene) in str(err.value)


def test_strict_yaml_runs_in_front_of_the_workflow(tmp_path):
    """The one subprocess: Snakemake parses the workflow, common.smk refuses the file."""
    import shutil

    shutil.copy2(ROOT / "Snakefile", tmp_path / "Snakefile")
    for d in ("workflow", "config", "profiles", "paper", "examples"):
        shutil.copytree(ROOT / d, tmp_path / d, ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    text = (ROOT / "config" / "ci.yaml").read_text().replace("  alpha: 0.2", "  alpha: 0.2\n  alpha: 0.1", 1)
    (tmp_path / "bad.yaml").write_text(text)
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    proc = subprocess.run([str(Path(sys.prefix) / "bin" / "snakemake"), "-n", "reproduce-all", "--cores", "1",
                           "--configfile", "bad.yaml"], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    lines = [l for l in (proc.stdout + proc.stderr).splitlines()
             if l.strip() and not l.startswith("Using workflow specific profile")]
    assert proc.returncode == 1 and len(lines) == 1, lines
    assert lines[0].startswith("config key infsup.alpha: given twice")


def test_user_space_empty_on_small_n(tmp_path, capsys):
    """A user space may be empty on small N (continuous P_1 vanishing at Γ's ends, k = 1, N = 1):
    it registers, and the N that leaves it empty is refused naming the case, N and k."""
    path = write_module(tmp_path, "small", "def space():\n    return SpaceSpec('U-small', 'u', '', good_build, "
                                           "lambda k: k)\n")
    ref = f"{path}:space"
    code, line = run_cli(capsys, "beta", "--space", ref, "--k", "1", "--N1", "1", "--N2", "1", "--dry-run")
    assert code == 2 and "case U-small" in one_line(line) and "dim M_h = 0" in line and "k = 1" in line, line
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["spaces"] = [*cfg.get("spaces", []), ref]
    cfg["infsup"]["cases"] = {"U-small": [1]}  # alone: T3 would be refused on N = 1 first
    cfg["infsup"]["N"] = [1, *cfg["infsup"]["N"]]
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith("config key infsup.N[0]: case U-small with k = 1 has dim M_h = 0")


# ------------------------------------------------------------------ issue 39, item 5: edge dropping in the config
@pytest.mark.parametrize("mutate, key, needle", [
    (lambda ed, fc: ed.update(theta=[1.0, 0.05, 0.03, 0.02, 0.015, 1e-12]), "studies.membranes3d.edge_dropping.theta[5]",
     "allowed 4e-09 <= θ <= 1"),
    (lambda ed, fc: fc.update(cases=["T3", "T4", "T5", "DUAL"]), "studies.membranes3d.edge_dropping.k[0]",
     "k = 1 has no edge case among studies.membranes3d.cases"),
])
def test_edge_dropping_config_is_refused_not_computed_as_garbage(mutate, key, needle):
    """θ below what the geometry resolves computed θ = 0 and turned the decay claims into FAIL;
    a k without an edge case among face.cases computed nothing. Both refused, naming the key."""
    cfg = copy.deepcopy(CI_CONFIG)
    mutate(cfg["studies"]["membranes3d"]["edge_dropping"], cfg["studies"]["membranes3d"])
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith(f"config key {key}") and needle in one_line(err.value), err.value


# ------------------------------------------------------------------ 6. issue 50, item 8: hostile config and API values

FULL_CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.mark.parametrize("key", ["../../victim", "/home/user", "a/b", "..", "x y", ""])
def test_a_producer_name_that_is_a_path_is_refused(key):
    """A code's name is a folder of the producers' workdir, emptied before each export: a path
    (absolute, with ``..`` or ``/``) deleted the user's files outside the project."""
    cfg = copy.deepcopy(FULL_CONFIG)
    codes = cfg["producers"]["codes"]
    codes[key] = codes.pop(next(iter(codes)))
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith("config key producers.codes:") and repr(key) in str(err.value)


@pytest.mark.parametrize("levels, needle", [([16, 32], "producers.codes.getfem.N"), ([16, 16, 32], "producers.codes.getfem.N"),
                                             ([16, 32, 1024], "producers.codes.getfem.N[2]")])
def test_a_codes_own_levels_are_checked_like_the_sections(levels, needle):
    """``codes.<name>.N`` (GetFEM's own levels): at least 3, distinct, each in [2, 512], as the section's."""
    check_config(copy.deepcopy(FULL_CONFIG), SCHEMA)  # the shipped levels pass (a refusal raises)
    cfg = copy.deepcopy(FULL_CONFIG)
    cfg["producers"]["codes"]["getfem"]["N"] = levels
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith(f"config key {needle}"), err.value


@pytest.mark.parametrize("space", ["../x", "/abs", "..", "a/b"])
def test_a_producer_space_that_is_a_path_is_refused(space):
    cfg = copy.deepcopy(FULL_CONFIG)
    next(iter(cfg["producers"]["codes"].values()))["spaces"][0] = space
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert one_line(err.value).startswith("config key producers.codes.") and "spaces[0]" in str(err.value)


@pytest.mark.parametrize("target", ["../victim", "../victim/sub", "kratos/../..", ".", "link/x"])
def test_the_producers_stage_deletes_only_inside_its_workdir(tmp_path, target):
    """Defence in depth (the config check comes first): a folder resolving outside the workdir,
    or the workdir itself, is never deleted."""
    from infsup_contact.study.producers import _empty_dir

    workdir, victim = tmp_path / "work", tmp_path / "victim"
    (victim / "sub").mkdir(parents=True)
    (victim / "sub" / "file").write_text("keep me")
    (workdir / "kratos").mkdir(parents=True)
    (workdir / "link").symlink_to(victim)
    with pytest.raises(InputError) as err:
        _empty_dir(workdir / target, workdir)
    assert err.value.key == "producers.codes" and (victim / "sub" / "file").read_text() == "keep me"
    _empty_dir(workdir / "kratos" / "dual_k0", workdir)  # inside: accepted
    assert (workdir / "kratos").is_dir() and not (workdir / "kratos" / "dual_k0").exists()


def test_face_n_equal_one_at_k_one_is_refused():
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["studies"]["membranes3d"].update(k=[1], cases=["T3", "R5.2", "DUAL"], N=[1, 4, 6, 8])
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = one_line(err.value)
    assert text.startswith("config key studies.membranes3d.N[0]") and "T3 with k = 1" in text and "dim M_h = 0" in text


@pytest.mark.parametrize("section, n", [("membranes3d", 64), ("elastic3d", 16)])
def test_face_jobs_are_counted_in_the_memory_check(section, n):
    """The face studies' β jobs have the command line's estimate (resources.beta_estimate,
    dim 3); a local run is refused when the largest exceeds the machine's memory (here a
    machine of 2 GB: the CI config's own largest job fits in it)."""
    from infsup_contact.config.memory import check_job_memory, job_estimates

    limit = 2e9
    check_job_memory(CI_CONFIG, limit)
    cfg = copy.deepcopy(CI_CONFIG)
    cfg["studies"][section]["N"] = sorted({*cfg["studies"][section]["N"], n})
    check_config(cfg, SCHEMA)
    assert any(job.startswith(f"{section} beta") for _, job, _ in job_estimates(cfg))
    with pytest.raises(ConfigError) as err:
        check_job_memory(cfg, limit)
    assert one_line(err.value).startswith(f"config key studies.{section}.N:") and f"{n}x{n}" in str(err.value)


def test_numpy_integer_scalars_are_the_integers_they_are():
    """The API takes numpy integer scalars (k=np.int64(2), N1=np.int32(4), seed=np.int64(3)):
    the same request, the same row (they were a TypeError)."""
    import infsup_contact as ic

    plain = ic.beta(case="T3", k=1, N1=4, N2=4, family="perturbed", seed=3, norm="L2")
    numpy = ic.beta(case="T3", k=np.int64(1), N1=np.int32(4), N2=np.int16(4), family="perturbed",
                    seed=np.int64(3), norm="L2")
    assert numpy.drop(columns=[c for c in numpy if c.startswith("t_")]).equals(
        plain.drop(columns=[c for c in plain if c.startswith("t_")]))
    with pytest.raises(InputError):
        ic.beta(case="T3", k=np.float64(1.5), N1=4, N2=4)


def test_an_input_error_survives_pickling_whole():
    """A worker process's error reaches the parent as raised (solvers/side_by_side.py): the same
    class, message, key, allowed values and value got; a subclass with its own constructor too."""
    import pickle

    from infsup_contact.errors import InputError
    from infsup_contact.systems.file_checks import SystemFileError

    for err in (InputError("N", "a positive integer", got=-3), SystemFileError("/tmp/A.mtx", "cut after 3 lines")):
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is type(err) and str(back) == str(err) and back.args == err.args
        assert (back.key, back.allowed, back.got) == (err.key, err.allowed, err.got)
