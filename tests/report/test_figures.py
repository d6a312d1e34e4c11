"""Figures stage: every figure function draws synthetic tables into a PDF and a PNG, all
figures share one case→colour map, and the figure-5 profiles have the expected columns."""
import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from infsup_contact.report import style as plotting
from infsup_contact.discretization.spaces.registry import PAPER_CASES

CASE_IDS = (*PAPER_CASES, "DUAL", "DUAL-ALL")  # the built-in spaces (users' spaces register later)

SCRIPTS = Path(__file__).resolve().parents[2] / "workflow" / "scripts"
FIGURE_SCRIPTS = ("fig_model_problem", "fig_beta", "fig_families", "fig_contact_solutions",
                  "fig_convergence", "fig_speed_accuracy")


def load_script(name):
    """Import workflow/scripts/NAME.py as a module (its Snakemake part does not run)."""
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def scripts():
    return {name: load_script(name) for name in FIGURE_SCRIPTS}


@pytest.fixture
def drawn(monkeypatch, scripts):
    """Record the colours of every line drawn before a figure is saved."""
    record = []
    real = plotting.save_figure

    def spy(fig, pdf, png):
        record.append({line.get_color() for ax in fig.get_axes() for line in ax.get_lines()})
        real(fig, pdf, png)

    for module in scripts.values():
        monkeypatch.setattr(module, "save_figure", spy)
    return record


def assert_written(tmp_path, stem):
    pdf, png = tmp_path / f"{stem}.pdf", tmp_path / f"{stem}.png"
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 1000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 1000
    assert not list(tmp_path.glob(f".{stem}*"))  # no temporary file left behind


# ------------------------------------------------------------------ synthetic tables
CASES_BY_K = {1: ["T3", "R5.2", "R5.4", "DUAL", "DUAL-ALL"], 2: ["T3", "R5.2", "T4", "R5.4", "T5", "DUAL", "DUAL-ALL"]}
KERNEL = {"R5.2": 2, "R5.4": 1, "DUAL-ALL": 2}


def beta_table():
    rows = []
    pairs = [(4, 4), (8, 8), (16, 16), (6, 4), (12, 8)]
    for fam in ("structured", "perturbed"):
        for k, cases in CASES_BY_K.items():
            for n1, n2 in pairs:
                for mm in ("omega2", "union"):
                    for norm in ("H", "L2"):
                        for case in cases:
                            h = 1 / n2
                            b = 0.9 * (h ** 0.5 if norm == "L2" else 1.0)
                            if mm == "union" and n1 != n2 and fam == "perturbed":
                                b *= h ** 3
                            kd = KERNEL.get(case, 0)
                            rows.append(dict(case=case, k=k, family=fam, N1=n1, N2=n2, multiplier_mesh=mm, c1=1.0,
                                             c2=1.0, norm=norm, beta=0.0 if kd else b, kernel_dim=kd,
                                             structural_kernel_dim=kd, smallest_nonzero=b * (h if kd == 1 else 1)))
    return pd.DataFrame(rows)


def contact_and_rates():
    rows, rates = [], []
    for k, cases in CASES_BY_K.items():
        for case in cases:
            for n in (4, 8, 16):
                h = 1 / n
                rows.append(dict(scene="manufactured", scene_kind="manufactured", case=case, k=k, family="structured",
                                 N1=n, N2=n, energy_error=h ** k, l2_error=h ** (k + 1),
                                 lambda_l2_error=h ** (k - 0.5), lambda_hm12_error=h ** k * (2 if case in KERNEL else 1)))
            for m in ("energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error"):
                rates.append(dict(scene="manufactured", case=case, k=k, family="structured", measure=m,
                                  slope=float(k), stderr=0.01, points=3, h_min=1 / 16, expected=float(k)))
    return pd.DataFrame(rows), pd.DataFrame(rates)


def speed_accuracy_csv(tmp_path, benchmarks_schema=False):
    """The minimal schema, or the benchmarks stage's (family column, Pareto flags)."""
    rows = [dict(scene=scene, case=case, k=k, N=n, seconds=1e-3 * n ** 2 * k, energy_error=n ** -k,
                 lambda_hm12_error=0.5 * n ** -k)
            for scene in ("manufactured", "membranes") for k, cases in CASES_BY_K.items() for case in cases
            for n in (4, 8, 16)]
    frame = pd.DataFrame(rows)
    if benchmarks_schema:
        frame = frame.assign(family="structured", pareto_energy=frame.N == 16, pareto_lambda=False)
    path = tmp_path / "speed_accuracy.csv"
    frame.to_csv(path, index=False)
    return pd.read_csv(path)


# ---------------------------------------------------------------------------- tests
def test_one_colour_map_for_every_figure(scripts):
    for name, module in scripts.items():
        assert module.CASE_COLORS is plotting.CASE_COLORS, name
    assert tuple(plotting.CASE_COLORS)[:len(CASE_IDS)] == CASE_IDS
    colours = [plotting.CASE_COLORS[c] for c in CASE_IDS]
    assert len(set(colours)) == len(colours)
    assert set(colours) <= set(plotting.OKABE_ITO.values())  # colour-vision-deficiency safe
    assert len({plotting.CASE_MARKERS[c] for c in CASE_IDS}) == len(CASE_IDS)
    for case in CASE_IDS:
        style = plotting.case_style(case, k=2)
        assert style["color"] == plotting.CASE_COLORS[case]
        assert style["linestyle"] == ("-" if case in ("T3", "T4", "T5", "DUAL") else "--")


def test_fig1_model_problem(tmp_path, scripts):
    scripts["fig_model_problem"].plot_model_problem(tmp_path / "f1.pdf", tmp_path / "f1.png")
    assert_written(tmp_path, "f1")


@pytest.mark.parametrize("norm", ["H", "L2"])
def test_fig2_fig3_beta(tmp_path, scripts, drawn, norm):
    scripts["fig_beta"].plot_beta(beta_table(), tmp_path / "f.pdf", tmp_path / "f.png", norm=norm)
    assert_written(tmp_path, "f")
    assert {plotting.CASE_COLORS[c] for c in CASE_IDS} <= drawn[0]


def test_fig4_families(tmp_path, scripts, drawn):
    mod = scripts["fig_families"]
    meshes = mod.default_meshes(panels=(("structured", "structured", 2, 2), ("non-matching", "perturbed", 3, 2)))
    assert len(meshes[1][3]) == 2 and meshes[1][3][0][1].shape[1] == 3
    mod.plot_families(beta_table(), meshes, tmp_path / "f4.pdf", tmp_path / "f4.png")
    assert_written(tmp_path, "f4")
    assert plotting.CASE_COLORS["T3"] in drawn[0]


def test_fig5_contact_solutions_from_profiles(tmp_path, scripts, drawn):
    from infsup_contact.study.contact.profiles import contact_profiles

    gamma, field = contact_profiles(["T4", "R5.4"], 2, 4)
    scripts["fig_contact_solutions"].plot_contact_solutions(gamma, field, tmp_path / "f5.pdf", tmp_path / "f5.png")
    assert_written(tmp_path, "f5")
    assert {plotting.CASE_COLORS["T4"], plotting.CASE_COLORS["R5.4"]} <= drawn[0]


def test_fig6_convergence(tmp_path, scripts, drawn):
    contact, rates = contact_and_rates()
    scripts["fig_convergence"].plot_convergence(contact, rates, tmp_path / "f6.pdf", tmp_path / "f6.png",
                                                "manufactured")  # the scene of contact_and_rates()
    assert_written(tmp_path, "f6")
    assert {plotting.CASE_COLORS[c] for c in CASE_IDS} <= drawn[0]


@pytest.mark.parametrize("benchmarks_schema", [False, True])
def test_fig7_speed_accuracy(tmp_path, scripts, drawn, benchmarks_schema):
    table = speed_accuracy_csv(tmp_path, benchmarks_schema)
    scripts["fig_speed_accuracy"].plot_speed_accuracy(table, tmp_path / "f7.pdf", tmp_path / "f7.png")
    assert_written(tmp_path, "f7")
    assert {plotting.CASE_COLORS[c] for c in CASE_IDS} <= drawn[0]


def test_pareto_front():
    front = load_script("fig_speed_accuracy").pareto_front
    t = np.array([1.0, 2.0, 3.0, 2.5, 0.5, np.nan])
    e = np.array([1.0, 0.5, 0.6, 0.1, 2.0, 0.01])
    assert front(t, e).tolist() == [True, True, False, True, True, False]
    assert front([1.0, 1.0, 2.0], [0.5, 0.5, 0.5]).tolist() == [True, True, False]  # duplicates both kept


def test_profiles_columns_on_tiny_mesh():
    from infsup_contact.study.contact.profiles import FIELD_COLUMNS, GAMMA_COLUMNS, contact_profiles

    gamma, field = contact_profiles(["T3"], 1, 4, per_interval=5)
    assert list(gamma.columns) == GAMMA_COLUMNS == ["case", "k", "N", "x", "quantity", "value"]
    assert list(field.columns) == FIELD_COLUMNS == ["case", "k", "N", "side", "x", "y", "u"]
    assert set(gamma.quantity) == {"gap", "lambda", "u1", "u2"}
    assert len(gamma) == 4 * 4 * 5  # quantities × intervals × samples per interval
    assert len(field) == 2 * 5 * 5 and set(field.side) == {1, 2}  # vertices of both 4×4 meshes
    wide = gamma.pivot_table(index="x", columns="quantity", values="value")
    assert np.allclose(wide.gap, wide.u2 - wide.u1)
    assert (gamma.x.between(0, 1)).all() and np.isfinite(gamma.value).all()
    assert field[field.side == 1].y.between(0, 1).all() and field[field.side == 2].y.between(1, 2).all()
    # u = 0 on the Dirichlet edges (x = 0, x = 1, y = 0, y = 2)
    edge = field[(field.x == 0) | (field.x == 1) | (field.y == 0) | (field.y == 2)]
    assert np.abs(edge.u).max() < 1e-12


def test_every_registered_marker_shows_its_fill_style():
    """Figures tell k apart by the marker's fill style: every space's marker has a body."""
    from infsup_contact.report.style import CASE_MARKERS, WIDE_MARKERS

    assert {case: m for case, m in CASE_MARKERS.items() if m not in WIDE_MARKERS} == {}
