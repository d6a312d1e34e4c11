"""Readers, manifest and the checks of real exports: every bad input is one line naming the
file (exit code 2 on the command line), every repair leaves β_h what it must be."""
from __future__ import annotations

import gzip
import io
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from infsup_contact.cli import main
from infsup_contact.systems.engine import level_spectrum
from infsup_contact.systems.export import matrix_bytes, write_system
from infsup_contact.systems.levels import load_level, system_rows
from infsup_contact.systems.manifest import load_manifest
from infsup_contact.systems.hb_petsc import MAT_FILE_CLASSID, petsc_binary_bytes, read_petsc_binary
from infsup_contact.systems.readers import SystemFileError, read_matrix

DATA = Path(__file__).resolve().parents[1] / "data" / "petsc"


# ------------------------------------------------------------------ readers

@pytest.mark.parametrize("indices", ["32bit", "64bit"])
def test_petsc_reader_reads_petsc_reference_files(indices):
    """Files written by PETSc's own PetscBinaryIO.py (tests/data/petsc/README.md)."""
    expected = np.load(DATA / "expected.npz")
    for key in ("A", "B"):
        got = read_petsc_binary(DATA / f"{key}_{indices}.petsc")
        assert got.shape == expected[key].shape
        assert np.array_equal(got.toarray(), expected[key])


def test_petsc_writer_is_byte_identical_to_the_reference():
    expected = np.load(DATA / "expected.npz")
    for key in ("A", "B"):
        assert petsc_binary_bytes(sp.csr_matrix(expected[key])) == (DATA / f"{key}_32bit.petsc").read_bytes()


def test_petsc_layout_spelled_out():
    """The layout of the PETSc manual: big-endian int32 class id, M, N, nz, row lengths,
    column indices, then float64 values."""
    A = sp.csr_matrix(np.array([[2.0, 0.0, -1.5], [0.0, 0.0, 0.0]]))
    raw = petsc_binary_bytes(A)
    head = np.frombuffer(raw, ">i4", 4 + 2 + 2)
    assert head.tolist() == [MAT_FILE_CLASSID, 2, 3, 2, 2, 0, 0, 2]
    assert np.frombuffer(raw, ">f8", 2, offset=32).tolist() == [2.0, -1.5]
    dense = np.arange(6.0).reshape(2, 3)  # MATDENSE: nz = -1 and M·N values row by row
    raw = np.array([MAT_FILE_CLASSID, 2, 3, -1], ">i4").tobytes() + dense.astype(">f8").tobytes()
    path = Path(pytest.importorskip("tempfile").mkdtemp()) / "D.petsc"
    path.write_bytes(raw)
    assert np.array_equal(read_petsc_binary(path), dense)


@pytest.mark.parametrize("fmt", ["mtx", "npz", "petsc"])
@pytest.mark.parametrize("dense", [False, True])
def test_every_format_round_trips(tmp_path, fmt, dense):
    rng = np.random.default_rng(1)
    M = sp.random(7, 5, density=0.4, random_state=rng, format="csr")
    M = M.toarray() if dense else M
    path = tmp_path / f"M.{'petsc' if fmt == 'petsc' else fmt}"
    path.write_bytes(matrix_bytes(M, fmt))
    got = read_matrix(path)
    assert np.array_equal(got.toarray() if sp.issparse(got) else got, M.toarray() if sp.issparse(M) else M)


def test_mtx_gz_and_harwell_boeing(tmp_path):
    M = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    with gzip.open(tmp_path / "M.mtx.gz", "wb") as fh:
        fh.write(matrix_bytes(M, "mtx"))
    assert np.array_equal(read_matrix(tmp_path / "M.mtx.gz").toarray(), M.toarray())
    scipy.io.hb_write(str(tmp_path / "M.rua"), sp.csc_matrix(M))
    assert np.array_equal(read_matrix(tmp_path / "M.rua").toarray(), M.toarray())


@pytest.mark.parametrize("name, content, found", [
    ("A.mtx", b"", "empty file"),
    ("A.mtx", b"not a matrix market file\n", "MatrixMarket banner"),
    ("A.npz", b"%%MatrixMarket matrix coordinate real general\n1 1 1\n1 1 2\n", "not a zip archive"),
    ("A.petsc", np.array([MAT_FILE_CLASSID, 3, 3, 9], ">i4").tobytes() + b"\0" * 20, "truncated"),
    ("A.petsc", np.array([1211214, 3], ">i4").tobytes() + b"\0" * 24, "not the matrix class id"),
    ("A.mtx", b"%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 2\n", "not a readable MatrixMarket"),
    ("A.txt", b"1 2 3", "unknown extension"),
])
def test_bad_files_are_one_line_naming_the_file(tmp_path, name, content, found):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(SystemFileError) as err:
        read_matrix(path)
    text = str(err.value)
    assert str(path) in text and found in text and "\n" not in text


# ------------------------------------------------------------------ checks on a small system

def _system(n=12, m=4):
    """A 1D Laplacian (SPD) and a B touching a few dofs."""
    A = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    B = sp.csr_matrix((np.ones(m), (np.arange(m), 2 * np.arange(m) + 1)), shape=(m, n))
    return A, B, sp.identity(m, format="csr")


def _manifest(tmp_path, A, B, G, extra="", levels=3, level_extra=""):
    write_system(tmp_path, [(1.0 / (i + 1), A, B, G) for i in range(levels)], "mtx", "toy")
    path = tmp_path / "levels.yaml"
    text = path.read_text().replace("norm: given\n", "norm: given\n" + extra)
    if level_extra:
        text = text.replace("G0.mtx}", "G0.mtx, " + level_extra + "}")
    path.write_text(text)
    return load_manifest(path)


def _beta(A, B, G):
    return level_spectrum(A, B, G).beta


def test_tgv_penalties_are_eliminated_with_the_same_beta(tmp_path):
    A, B, G = _system()
    pen = A.tolil()
    for i in (0, 11):  # Dirichlet by penalty at both ends, B touches neither
        pen[i, i] = 1e30
    m = _manifest(tmp_path, pen.tocsr(), B, G)
    lv = load_level(m, m.levels[0])
    assert lv.removed == 2 and "2 Dirichlet penalty rows" in lv.notes[0]
    keep = np.arange(1, 11)
    assert abs(_beta(lv.A, lv.B, lv.G) - _beta(A[keep][:, keep], B[:, keep], G)) <= 1e-12
    m2 = _manifest(tmp_path, pen.tocsr(), B, G, extra="tgv: refuse\n")
    with pytest.raises(SystemFileError, match="Dirichlet penalty rows.*tgv: refuse"):
        load_level(m2, m2.levels[0])


def test_identity_rows(tmp_path):
    A, B, G = _system()
    big = sp.block_diag([A, sp.identity(2)], format="csr")  # 2 constrained dofs left as identity
    m = _manifest(tmp_path, big, sp.hstack([B, sp.csr_matrix((4, 2))], format="csr"), G)
    lv = load_level(m, m.levels[0])
    assert lv.removed == 2 and abs(_beta(lv.A, lv.B, lv.G) - _beta(A, B, G)) <= 1e-12
    # B assembled over them too: a unit row is a constrained dof (v = 0), so B's entries there are
    # dropped, exactly as over a penalty row (tests/systems/test_systems_constrained.py has the whole table)
    Bover = sp.hstack([B, sp.csr_matrix(np.array([[1.0, 0]] * 4))], format="csr")
    m = _manifest(tmp_path, big, Bover, G)
    lv = load_level(m, m.levels[0])
    assert lv.removed == 2 and "B's 4 entries on them dropped" in " ".join(lv.notes)
    assert abs(_beta(lv.A, lv.B, lv.G) - _beta(A, B, G)) <= 1e-12


def test_declared_constrained_dofs(tmp_path):
    A, B, G = _system()
    m = _manifest(tmp_path, A, B, G, level_extra="constrained: [0, 11]")
    lv = load_level(m, m.levels[0])
    assert lv.A.shape == (10, 10) and lv.removed == 2
    m = _manifest(tmp_path, A, B, G, level_extra="constrained: [1]")  # B touches dof 1: v = 0 there
    lv = load_level(m, m.levels[0])
    assert lv.removed == 1 and "B's 1 entries on them dropped" in lv.notes[0]
    keep = np.setdiff1d(np.arange(12), [1])
    assert lv.B.shape == (4, 11) and lv.B.nnz == B[:, keep].nnz == 3


@pytest.mark.parametrize("damage, found", [
    (lambda A, B, G: (A + sp.csr_matrix(([0.5], ([0], [1])), shape=A.shape), B, G), "not symmetric"),
    (lambda A, B, G: (A - sp.csr_matrix(([1.0, 1.0], ([0, 11], [0, 11])), shape=A.shape), B, G), "singular"),
    (lambda A, B, G: (A - 1.0 * sp.identity(12), B, G), "not positive definite"),
    (lambda A, B, G: (A, B, sp.diags([1.0, 1.0, 0.0, 1.0])), "zero rows"),
    (lambda A, B, G: (A, B, sp.diags([1.0, 1.0, -1.0, 1.0])), "G is not positive definite"),
    (lambda A, B, G: (A, B[:, :11], G), "expected 4 x 12"),
    (lambda A, B, G: (A.multiply(np.where(np.eye(12)[0:1].T @ np.ones((1, 12)) > 0, np.nan, 1.0)).tocsr(), B, G),
     "NaN/inf"),
])
def test_damaged_systems_are_refused_naming_the_file(tmp_path, damage, found):
    m = _manifest(tmp_path, *damage(*_system()))
    with pytest.raises(SystemFileError) as err:
        system_rows(m, notes=io.StringIO())
    text = str(err.value)
    assert found in text and any(f"{key}0.mtx" in text for key in "ABG") and "\n" not in text


def test_floating_body_reports_the_null_vector():
    """Pure Neumann Laplacian: the constants are its null space; the message says how small
    A x is for the null vector found."""
    A, B, G = _system()
    A = A.tolil()
    A[0, 0] = A[11, 11] = 1.0
    from infsup_contact.systems.checks import check_positive_definite

    with pytest.raises(SystemFileError, match=r"1 zero pivots of 12 \(a floating body.*null vector x has"):
        check_positive_definite(A.tocsc(), "A.mtx")
    with pytest.raises(SystemFileError, match=r"2 zero pivots of 24"):  # two floating bodies
        check_positive_definite(sp.block_diag([A, A], format="csc"), "A.mtx")


def test_manifest_errors(tmp_path):
    A, B, G = _system()
    m = _manifest(tmp_path, A, B, G)
    text = m.path.read_text()
    for bad, found in ((text.replace("h: 0.5", "h: 2.0"), "does not decrease"),
                       (text.replace("norm: given", "norm: H1"), "norm: 'H1' is not one of"),
                       (text + "colour: red\n", "unknown key 'colour'"),
                       (text.replace("A1.mtx", "A9.mtx"), "no such file"),
                       ("levels: 3\n", "'levels' must be a non-empty list")):
        m.path.write_text(bad)
        with pytest.raises(SystemFileError, match=found):
            system_rows(load_manifest(m.path), notes=io.StringIO())


def test_levels_with_fewer_dofs_when_finer_are_refused(tmp_path):
    A, B, G = _system()
    A2, B2, G2 = _system(n=10)
    write_system(tmp_path, [(0.5, A, B, G), (0.25, A2, B2, G2), (0.125, A, B, G)], "mtx", "swapped")
    with pytest.raises(SystemFileError, match=r"levels\[1\].*mismatched levels"):
        system_rows(load_manifest(tmp_path / "levels.yaml"), notes=io.StringIO())


def test_cli_bad_input_is_one_line_exit_2(tmp_path, capsys):
    A, B, G = _system()
    m = _manifest(tmp_path, A, B, G)
    (tmp_path / "B1.mtx").write_bytes(b"%%MatrixMarket matrix coordinate real general\n4 12 3\n1 1 1\n")
    for argv in (["verdict", "--system", str(m.path)], ["verdict", "--system", str(m.path), "--dry-run"],
                 ["beta", "--system", str(m.path)], ["verdict", "--system", str(tmp_path / "none.yaml")],
                 ["verdict", "--system", str(m.path), "--k", "2"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("infsup-contact: error: ") and err.count("\n") == 1 and "Traceback" not in err
    for argv, flag in ((["verdict", "--system", str(m.path), "--norm", "L2"], "--norm"),  # never ignored silently
                       (["beta", "--system", str(m.path), "--c1", "2"], "--c1"),
                       (["verdict", "--system", str(m.path), "--N", "4", "8", "16"], "--N")):
        assert main(argv) == 2
        assert f"invalid {flag} " in capsys.readouterr().err


def test_pardiso_inertia_certifies_only_a_clean_spd_matrix(monkeypatch):
    """From PARDISO_CHECK_MIN rows PARDISO's LDLᵀ inertia certifies A at once (n positive pivots,
    none negative, none perturbed); a singular or indefinite A still gets SuperLU's diagnosis,
    the same messages as below the gate."""
    from infsup_contact.la import pardiso
    from infsup_contact.systems import checks

    if not pardiso.available():
        pytest.skip("MKL PARDISO not loadable here")
    monkeypatch.setattr(checks, "PARDISO_CHECK_MIN", 1)
    A, B, G = _system()
    assert pardiso.inertia(A) == (A.shape[0], 0, 0)
    assert checks.check_positive_definite(A.tocsc(), "A.mtx") is None        # certified by PARDISO
    floating = A.tolil()
    floating[0, 0] = floating[11, 11] = 1.0
    pos, neg, perturbed = pardiso.inertia(floating.tocsr())
    assert neg == 0 and perturbed >= 1                                       # the constants: a zero pivot
    with pytest.raises(SystemFileError, match=r"1 zero pivots of 12 \(a floating body.*null vector x has"):
        checks.check_positive_definite(floating.tocsc(), "A.mtx")
    shifted = (A - 2.0 * sp.identity(A.shape[0])).tocsc()
    n_neg = int(np.sum(np.linalg.eigvalsh(shifted.toarray()) < 0))
    assert n_neg > 0 and pardiso.inertia(shifted)[1] == n_neg                # Sylvester: the inertia
    with pytest.raises(SystemFileError, match="not positive definite"):
        checks.check_positive_definite(shifted, "A.mtx")
