"""Kratos names its MatrixMarket files ``.mm``: read like ``.mtx`` (``scipy.io.mmread``), with
the same checks, and a system written as ``.mm`` gets the verdict of the same system as ``.mtx``."""
from __future__ import annotations

import gzip

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.systems.export import matrix_bytes
from infsup_contact.systems.readers import SystemFileError, extension, read_matrix
from helpers.cli import run_in_process


def test_mm_and_mm_gz_read_as_matrix_market(tmp_path):
    M = sp.random(6, 4, density=0.5, random_state=np.random.default_rng(2), format="csr")
    (tmp_path / "M.mm").write_bytes(matrix_bytes(M, "mtx"))
    with gzip.open(tmp_path / "M.mm.gz", "wb") as fh:
        fh.write(matrix_bytes(M, "mtx"))
    assert extension(tmp_path / "M.mm.gz") == ".mm.gz"
    for name in ("M.mm", "M.mm.gz"):
        assert np.array_equal(read_matrix(tmp_path / name).toarray(), M.toarray())


@pytest.mark.parametrize("content, found", [
    (b"not a matrix market file\n", "MatrixMarket banner"),
    (b"%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 2\n", "MatrixMarket"),
    (b"%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 2.5e-0", "does not end with a newline"),
])
def test_a_damaged_mm_file_is_refused_as_an_mtx_is(tmp_path, content, found):
    for name in ("A.mm", "A.mtx"):
        (tmp_path / name).write_bytes(content)
        with pytest.raises(SystemFileError) as err:
            read_matrix(tmp_path / name)
        assert str(tmp_path / name) in str(err.value) and found in str(err.value)


def test_a_system_of_mm_files_gets_the_verdict_of_its_mtx_files(tmp_path):
    mtx, mm = tmp_path / "mtx", tmp_path / "mm"
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "1", "--N", "4", "8", "16", "--out", str(mtx)])
    assert code == 0, err
    mm.mkdir()
    for path in mtx.iterdir():
        if path.suffix == ".mtx":
            (mm / (path.stem + ".mm")).write_bytes(path.read_bytes())
        elif path.name == "levels.yaml":
            (mm / path.name).write_text(path.read_text().replace(".mtx", ".mm"))
        else:
            (mm / path.name).write_bytes(path.read_bytes())
    rows = []
    for d in (mtx, mm):
        code, out, err = run_in_process(["verdict", "--system", str(d / "levels.yaml")])
        assert code == 0, err
        rows.append(out.splitlines()[1].split(","))
    header = out.splitlines()[0].split(",")
    keep = [i for i, c in enumerate(header) if c not in ("seconds",)]
    assert [rows[0][i] for i in keep] == [rows[1][i] for i in keep]
    assert ".mm" in (mm / "levels.yaml").read_text()
