"""The face section's figures (report/figures/face.py, rule face_figures): drawn from tables of the
face study's schemas into a PDF and a PNG, every space without a kernel drawn in its own colour,
spaces with a kernel left out, the worst mode drawn with the values of its table."""
import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from infsup_contact.report import style as plotting
from infsup_contact.report.figures import face as face_figures

ROOT = Path(__file__).resolve().parents[2]


def assert_written(tmp_path, stem):
    pdf, png = tmp_path / f"{stem}.pdf", tmp_path / f"{stem}.png"
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 1000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 1000
    assert not list(tmp_path.glob(f".{stem}*"))  # no temporary file left behind


@pytest.fixture
def drawn(monkeypatch):
    """The figures each save: their axes' lines (colour, data) and scatter values."""
    record = []
    real = plotting.save_figure

    def spy(fig, pdf, png):
        record.append(fig.get_axes())
        real(fig, pdf, png)

    monkeypatch.setattr(plotting, "save_figure", spy)
    return record


def face_beta():
    rows = []
    for element, cases in (("hex", ("T3", "R5.2", "DUAL")), ("tet", ("T3", "T4"))):
        for k in (1, 2):
            for n in (4, 6, 8):
                for norm in ("H", "L2"):
                    for case in cases:
                        kernel = 4 * n * k if case == "R5.2" else 0
                        rows.append(dict(model="membranes3d", element=element, case=case, k=k, family="structured",
                                         N1=n, N2=n, multiplier_mesh="omega2", c1=1.0, c2=1.0, norm=norm,
                                         beta=0.0 if kernel else 0.8 / n ** (0.5 if norm == "L2" else 0.0),
                                         kernel_dim=kernel, structural_kernel_dim=kernel))
    rows.append(dict(rows[0], N1=4, N2=5, beta=0.7))  # a non-matching pair: not drawn
    return pd.DataFrame(rows)


def edge_table():
    theta = np.array([1.0, 0.5, 0.1, 0.05, 0.01])
    return pd.DataFrame([dict(case=case, k=k, N=4, theta=t, beta_H=0.9 * t ** (0.5 if case == "T3" else 0.0),
                              beta_L2=0.3, beta_H_resolved=True, beta_L2_resolved=True, beta_L2_kappa=0.3,
                              beta_L2_kappa_resolved=True, fit_theta_max=0.05, cond_S=10 / t, cond_S_kappa=10.0)
                         for case in ("T3", "DUAL") for k in (1, 2) for t in theta])


def alpha_table():
    rows = []
    for element in ("QUAD8", "QUAD9"):
        for a in (0.05, 0.125, 0.2, 0.3, 0.45):
            ok = not (element == "QUAD8" and a <= 0.125)
            for norm in ("H", "L2"):
                rows.append(dict(element=element, alpha=a, N=4, norm=norm, min_weight=a - 0.125, min_weight_gauss=0.0,
                                 accepted=ok, beta=(0.5 + a) if ok else np.nan))
    return pd.DataFrame(rows)


def checkerboard_modes():
    """A T4 worst mode as beta --worst-mode writes it (sixths of a 2 × 2 grid): ±1 by Kuhn triangle."""
    t = np.linspace(0.0, 1.0, 13)
    X, Y = np.meshgrid(t, t, indexing="ij")
    x, y = X.ravel(), Y.ravel()
    cell = np.minimum((x * 2).astype(int), 1) + np.minimum((y * 2).astype(int), 1)
    upper = (y * 2 % 1) > (x * 2 % 1)
    mu = np.where((cell + upper) % 2 == 0, 1.0, -1.0)
    return pd.DataFrame(dict(case="T4", multiplier_mesh="omega2", c1=1.0, c2=1.0, norm="L2", beta=0.0, x=x, y=y,
                             mu=mu))


def test_face_beta_figure(tmp_path, drawn):
    beta = face_beta()
    face_figures.plot_face_beta(beta, tmp_path / "f10.pdf", tmp_path / "f10.png")
    assert_written(tmp_path, "f10")
    hexes, tets = drawn[0]
    assert "hexahedra" in hexes.get_title() and "tetrahedra" in tets.get_title()
    # one line per (space, k) without a kernel; R5.2 (a kernel: β_h = 0) is left out
    assert len(hexes.get_lines()) == 4 and len(tets.get_lines()) == 4
    colours = {line.get_color() for line in hexes.get_lines()}
    assert colours == {plotting.CASE_COLORS["T3"], plotting.CASE_COLORS["DUAL"]}
    for line in hexes.get_lines():  # matching meshes only, in h
        assert np.allclose(sorted(line.get_xdata()), [1 / 8, 1 / 6, 1 / 4])


def test_face_beta_figure_with_hex20(tmp_path, drawn):
    hex20 = pd.DataFrame([dict(case=case, N=n, norm=norm, dim_M=1, dim_W=1, kernel_dim=kernel, structural_kernel_dim=kernel,
                               kernel_decision="clear", beta=0.0 if kernel else 0.7, verdict="STABLE")
                          for case, kernel in (("Q8", 0), ("Q8-ALL", 3), ("LIN0-Q8", 0))
                          for n in (4, 6, 8) for norm in ("H", "L2")])
    face_figures.plot_face_beta(face_beta(), tmp_path / "f.pdf", tmp_path / "f.png", hex20=hex20)
    assert_written(tmp_path, "f")
    third = drawn[0][2]
    assert "HEX20" in third.get_title()
    assert {line.get_label() for line in third.get_lines()} == {"Q8, k=2", "LIN0-Q8, k=2"}
    assert plotting.CASE_COLORS["Q8"] != plotting.CASE_COLORS["LIN0-Q8"]  # the QUAD8 spaces told apart


def test_face_beta_without_rows_is_one_clear_error(tmp_path):
    beta = face_beta().assign(kernel_dim=1)
    with pytest.raises(ValueError, match="no matching-mesh H rows"):
        face_figures.plot_face_beta(beta, tmp_path / "f.pdf", tmp_path / "f.png")


def test_face_studies_figure(tmp_path, drawn):
    modes = checkerboard_modes()
    face_figures.plot_face_studies(edge_table(), alpha_table(), modes, tmp_path / "f11.pdf", tmp_path / "f11.png")
    assert_written(tmp_path, "f11")
    a, b, c, d = drawn[0][:4]
    assert len(a.get_lines()) == 4 and len(b.get_lines()) == 8  # (space, k): cond plain and κ-scaled
    alpha_lines = [line for line in c.get_lines() if line.get_linestyle() in ("-", "--")]
    quad8_h = next(line for line in alpha_lines if line.get_label() == "TDUAL-Q8, H")
    assert np.all(np.asarray(quad8_h.get_xdata()) > 0.125)  # refused α are not on the line
    (points,) = d.collections
    assert np.array_equal(points.get_array(), modes.mu.to_numpy())  # the table's values, unchanged


def test_the_rule_draws_the_real_worst_mode(tmp_path):
    """fig_face.py's mode table is what beta --worst-mode writes: read under the worst_mode schema."""
    from infsup_contact.io import read_table
    from tests.helpers.cli import run_in_process

    path = tmp_path / "modes.csv"
    code, _, err = run_in_process(["beta", "--model", "membranes3d", "--element", "tet", "--case", "T4", "--k", "2",
                                   "--N1", "2", "--N2", "2", "--norm", "L2", "--worst-mode", str(path)])
    assert code == 0, err
    modes = read_table(path, "worst_mode")
    face_figures.plot_face_studies(edge_table(), alpha_table(), modes, tmp_path / "f.pdf", tmp_path / "f.png")
    assert_written(tmp_path, "f")


def test_script_calls_the_library():
    spec = importlib.util.spec_from_file_location("fig_face", ROOT / "workflow" / "scripts" / "fig_face.py")
    text = Path(spec.origin).read_text()
    assert "plot_face_beta" in text and "plot_face_studies" in text and '"worst_mode"' in text
