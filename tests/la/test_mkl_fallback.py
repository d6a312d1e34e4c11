"""Without a loadable MKL runtime (no ``mkl`` wheel: pyproject installs it on Linux x86_64 only)
the 3D routes fall back to scipy with one note on stderr, and give the same Γ Schur complement."""
from __future__ import annotations

import pytest

from infsup_contact.la import mkl, pardiso


def _forget():
    mkl.mkl_rt.cache_clear()
    pardiso._library.cache_clear()


@pytest.fixture
def without_mkl(monkeypatch, tmp_path):
    """MKL as on a machine without the wheel: $INFSUP_MKL_RT names no library, lib/ holds none."""
    missing = tmp_path / "libmkl_rt.so.2"
    monkeypatch.setenv("INFSUP_MKL_RT", str(missing))
    monkeypatch.setattr(mkl.glob, "glob", lambda pattern: [])
    _forget()
    yield missing
    _forget()  # the next caller loads the real library again (the patches are undone first)


def test_missing_mkl_is_one_note_and_the_scipy_route(without_mkl, capsys):
    assert mkl.mkl_rt() is None and not mkl.available() and not pardiso.available()
    assert mkl.mkl_rt() is None  # cached: the note is printed once per process
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and str(without_mkl) in lines[0] and "scipy routes run" in lines[0], lines
    assert "Traceback" not in lines[0]


def _laplacian(n: int):
    """The 5-point Laplacian on an n × n grid (SPD), its last row of nodes taken as Γ."""
    import scipy.sparse as sp

    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    return (sp.kron(sp.eye(n), T) + sp.kron(T, sp.eye(n))).tocsc()


def test_the_fallback_route_gives_the_schur_complement_of_pardiso(monkeypatch, tmp_path):
    """A face (gamma_dim 2) above the dense-solves size takes PARDISO where MKL loads and the
    nested-dissection LU where it does not: the same S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ."""
    import numpy as np

    from infsup_contact.la import schur

    if not pardiso.available():
        pytest.skip("MKL PARDISO is not loadable here: nothing to compare the scipy route with")
    A, n_gamma = _laplacian(24), 24
    monkeypatch.setattr(schur, "SOLVES_MAX_WORK", 0)  # the large-problem branch on a small A
    with_mkl = schur.gamma_factorization(A, n_gamma, gamma_dim=2)
    monkeypatch.setenv("INFSUP_MKL_RT", str(tmp_path / "none.so"))
    monkeypatch.setattr(mkl.glob, "glob", lambda pattern: [])
    _forget()
    try:
        without = schur.gamma_factorization(A, n_gamma, gamma_dim=2)
    finally:
        monkeypatch.undo()
        _forget()
    assert (with_mkl.route, without.route) == ("pardiso", "nested")
    scale = np.abs(with_mkl.schur).max()
    assert np.abs(without.schur - with_mkl.schur).max() <= 1e-12 * scale


def test_the_route_is_told_gammas_dimension_never_assumes_it(monkeypatch):
    """``gamma_dim`` has no default (no caller's Γ is taken for the segment); PARDISO is a face's
    route only: a curve and a Γ not told (a foreign system) take the same SuperLU route, bit for
    bit; a dimension that is neither is refused naming the key."""
    import numpy as np

    from infsup_contact.errors import InputError
    from infsup_contact.la import schur

    A, n_gamma = _laplacian(24), 24
    with pytest.raises(TypeError):
        schur.gamma_factorization(A, n_gamma)
    with pytest.raises(InputError, match="gamma_dim"):
        schur.gamma_factorization(A, n_gamma, gamma_dim=3)
    monkeypatch.setattr(schur, "SOLVES_MAX_WORK", 0)  # the large-problem branch on a small A
    curve, untold = (schur.gamma_factorization(A, n_gamma, gamma_dim=d) for d in (1, None))
    assert curve.route == untold.route == "nested"
    assert np.array_equal(curve.schur, untold.schur)
