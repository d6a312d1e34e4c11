"""The notebook API beyond the command line's strings: ``space=`` a SpaceSpec or a function
defined in the notebook (loaded and checked as a FILE.py:FUNC space is), and ``certify``'s
``expect`` (and its own keywords, listed truthfully when one is wrong)."""
import dataclasses
from pathlib import Path

import pytest

import infsup_contact as ic
from infsup_contact.discretization.spaces.spec import SpaceSpec
from infsup_contact.errors import InputError
from helpers.cli import run_in_process

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = f"{ROOT / 'examples' / 'macro_p0.py'}:space"


def _example_spec() -> SpaceSpec:
    import runpy

    return runpy.run_path(str(ROOT / "examples" / "macro_p0.py"))["space"]()


def test_a_notebook_function_and_a_spec_are_the_file_space(tmp_path):
    """The same space three ways (under three ids, as a registry holds an id once): the same β."""
    spec = _example_spec()

    def space():  # as a notebook defines it
        return dataclasses.replace(spec, id="NB-P0-2h")

    as_file = ic.beta(space=EXAMPLE, k=1, N1=8, N2=8, norm="H")
    as_function = ic.beta(space=space, k=1, N1=8, N2=8, norm="H")
    as_spec = ic.beta(space=dataclasses.replace(spec, id="NB-P0-2h-spec"), k=1, N1=8, N2=8, norm="H")
    assert as_function.case[0] == "NB-P0-2h" and as_spec.case[0] == "NB-P0-2h-spec"
    assert as_file.beta[0] == as_function.beta[0] == as_spec.beta[0] > 0
    again = ic.verdict(space=space, k=1, N=[8, 16, 32])  # the same function again: the same entry
    assert again.space[0] == "NB-P0-2h" and again.verdict[0] == "STABLE"


def test_a_notebook_space_is_checked_as_a_file_space():
    bad = dataclasses.replace(_example_spec(), id="NB-BAD", degree=lambda k: 1)  # builds P_0, says P_1
    with pytest.raises(InputError) as err:
        ic.beta(space=bad, k=1, N1=8, N2=8)
    assert "NB-BAD" in str(err.value) and "local degree 1" in str(err.value)

    def build(k, x):  # the build function, not the one returning the SpaceSpec
        return None

    with pytest.raises(InputError) as err:
        ic.verdict(space=build, k=1)
    assert "function of no arguments returning a SpaceSpec" in str(err.value)
    with pytest.raises(InputError) as err:
        ic.beta(space=3, k=1, N1=8, N2=8)
    assert "a SpaceSpec" in str(err.value) and "FILE.py:FUNC" in str(err.value)


@pytest.fixture(scope="module")
def manifest(tmp_path_factory):
    out = tmp_path_factory.mktemp("export")
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "2", "--N", "8", "16", "32", "--out", str(out),
                                   "--force"])
    assert code == 0, err
    return out / "levels.yaml"


def test_certify_takes_expect_as_verdict_expect_does(manifest):
    code, _, _ = run_in_process(["verdict", "--system", str(manifest), "--expect", "unstable"])
    stable = ic.certify(manifest, expect="stable")
    unstable = ic.certify(manifest, expect="unstable")
    assert stable.verdict[0] == unstable.verdict[0] == "STABLE"
    assert (stable.attrs["met"], unstable.attrs["met"]) == (True, False)
    assert code == 1  # the command's exit code says the same
    assert ic.certify(manifest).attrs["met"] is None


def test_certify_refuses_a_keyword_naming_its_own_keywords(manifest):
    with pytest.raises(InputError) as err:
        ic.certify(manifest, expect="maybe")
    assert "stable, unstable" in str(err.value)
    with pytest.raises(InputError) as err:
        ic.certify(manifest, case="T3")
    text = str(err.value)
    assert "expect" in text and "slope_tolerance" in text and " N," not in text and "multiplier_mesh" not in text
