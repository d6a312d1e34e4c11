"""Issue 40, item 0: nothing silent, nothing unsafe on the foreign-system path.

Each test is one fault a hostile (or unlucky) user can produce with a small file: before the
fix it gave a wrong verdict, a segmentation fault, a silently misread number, unbounded memory
or an overwritten directory; now a verdict that says what it found, or one line on stderr
naming the file, exit code 2."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.cli import main
from infsup_contact.systems.engine import level_spectrum
from infsup_contact.systems.export import write_system
from infsup_contact.systems.levels import system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest

CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
NS = (8, 16, 32)


def _level(N, kind):
    """A system with β_h ≈ 0.7 on every level (stable), or made singular by ``kind``."""
    n, m = 2 * N, N // 2
    A = sp.diags([-0.1 * np.ones(n - 1), 2.0 * np.ones(n), -0.1 * np.ones(n - 1)], [-1, 0, 1], format="lil")
    B = sp.lil_matrix((m, n))
    for j in range(m):
        B[j, 2 * j + 1] = 1.0
    if kind == "zero_row":
        B[m - 1, :] = 0
    elif kind == "half_rank":  # rows pairwise equal
        for j in range(0, m, 2):
            B[j + 1, :] = B[j, :]
    elif kind == "more_rows":  # more multipliers than dofs
        B = sp.lil_matrix((n + 3, n))
        B[np.arange(n), np.arange(n)] = 1.0
        B[n:, :3] = np.eye(3)
    elif kind == "penalty":  # the only dof of the last row fixed by a penalty: the row is left uncoupled
        d = 2 * m - 1
        A[d, d], A[d, d - 1], A[d - 1, d], A[d, d + 1], A[d + 1, d] = 1e30, 0, 0, 0, 0
    return 1.0 / N, A.tocsr(), sp.csr_matrix(B), sp.identity(B.shape[0], format="csr")


def _write(tmp_path, kind, known_kernel=0):
    return write_system(tmp_path / kind, [_level(N, kind) for N in NS], "mtx", kind, known_kernel=known_kernel)


# ------------------------------------------------------------------ 1. a singular system is not STABLE

@pytest.mark.parametrize("kind, dims", [("zero_row", [1, 1, 1]), ("half_rank", [2, 4, 8]),
                                        ("more_rows", [3, 3, 3]), ("penalty", [1, 1, 1])])
def test_an_undeclared_kernel_is_unstable(tmp_path, capsys, kind, dims):
    """Before: STABLE, kernel_dim 0, exit 0 under --expect stable (the deficiency m − touched dofs
    was counted as 'proven' and discounted as if declared)."""
    path = _write(tmp_path, kind)
    out, rows = system_verdict(load_manifest(path), **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "UNSTABLE" and out["kernel_dim"] == max(dims) and out["beta_min"] == 0.0
    assert f"of dim {dims}" in out["evidence"] and "not declared (known_kernel: 0)" in out["evidence"]
    assert [r["known_kernel"] for r in rows] == [0, 0, 0]  # only what was declared
    assert [r["kernel_detected"] for r in rows] == dims
    assert main(["verdict", "--system", str(path), "--expect", "stable"]) == 1
    assert ",UNSTABLE," in capsys.readouterr().out


def test_a_declared_kernel_is_discounted(tmp_path):
    """The same zero row, declared (known_kernel: 1): β_h above it, STABLE."""
    out, rows = system_verdict(load_manifest(_write(tmp_path, "zero_row", known_kernel=1)), **CRITERION,
                               notes=io.StringIO())
    assert out["verdict"] == "STABLE" and out["kernel_dim"] == 0
    assert all(r["known_kernel"] == 1 and r["kernel_dim"] == 1 and r["beta"] > 0.7 for r in rows)


def test_a_nearly_repeated_row_is_unstable_either_way_never_stable(tmp_path):
    """Two rows of B equal but for 1e-14: the kernel decision is within a decade of round-off on
    a level (1e-14 x the row's max is a producer zero, so η holds that round-off and the pair
    is a kernel up to it: close on the coarse levels). The mode in question has β ~ 1e-14: as a
    kernel it is UNSTABLE, as a non-zero mode it is below the β floor, UNSTABLE too — so the
    verdict is UNSTABLE, saying so. With a floor below that β the two readings differ and the
    verdict is INCONCLUSIVE, the margins and the advice named. Never STABLE."""
    levels = []
    for N in NS:
        h, A, B, G = _level(N, "ok")
        B = B.tolil()
        B[1, :] = B[0, :]
        B[1, 3] = 1e-14
        levels.append((h, A, B.tocsr(), G))
    path = write_system(tmp_path, levels, "npz", "near")
    out, rows = system_verdict(load_manifest(path), **CRITERION, notes=io.StringIO())
    close = [r for r in rows if r["kernel_decision"] == "close"]
    assert close and all(r["kernel_decision"] == "close" or r["kernel_dim"] == 1 for r in rows)
    assert all(r["beta_uncertain"] < CRITERION["floor"] for r in close)
    assert out["verdict"] == "UNSTABLE" and "whichever way it is counted" in out["evidence"]
    below = min(r["beta_uncertain"] for r in close) / 10.0
    if below > 0.0:  # a floor under the mode's β: the count decides, and it is not decided
        out, _ = system_verdict(load_manifest(path), **dict(CRITERION, floor=below), notes=io.StringIO())
        assert out["verdict"] == "INCONCLUSIVE" and "margins" in out["evidence"] and "entry_rtol" in out["evidence"]
    assert main(["verdict", "--system", str(path), "--expect", "stable"]) == 1


def test_structural_kernel_is_detected_on_every_route():
    _, A, B, G = _level(16, "more_rows")
    for route in ("gamma-dense", "solves-dense", "shift-invert"):
        res = level_spectrum(A, B, G, route=route)
        assert res.kernel.proven == 0 and res.kernel.detected == 3 and res.beta == 0.0, route


# ------------------------------------------------------------------ 2. index arrays checked before scipy sees them

def _csr_npz(path, B, **override):
    arrays = dict(format=np.array("csr"), shape=np.array(B.shape), data=B.data, indices=B.indices, indptr=B.indptr)
    arrays.update(override)
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize("override, found", [
    (lambda B: dict(indices=B.indices + 10 ** 6), "column index 1000007 outside 0..15"),
    (lambda B: dict(indices=B.indices - 10 ** 6), "column index -999999 outside 0..15"),
    (lambda B: dict(indptr=B.indptr[::-1].copy()), "index pointers must rise from 0 to 4"),
    (lambda B: dict(indptr=B.indptr[:-1].copy()), "4 index pointers for 4 rows"),
    (lambda B: dict(data=B.data[:-1].copy()), "3 values but 4 column indices"),
    (lambda B: dict(format=np.array("bsr")), "'bsr' archive"),
    (lambda B: dict(shape=np.array([4, -16])), "not two integers >= 0"),
])
def test_npz_with_bad_indices_is_one_line_not_a_crash(tmp_path, capsys, override, found):
    """Before: exit 139 (segmentation fault, no message), after --dry-run said 'valid request'."""
    path = _write(tmp_path, "ok")
    B = sp.csr_matrix(_level(8, "ok")[2])
    _csr_npz(path.parent / "B0.npz", B, **override(B))
    path.write_text(path.read_text().replace("B0.mtx", "B0.npz"))
    for argv in (["--dry-run"], []):
        assert main(["verdict", "--system", str(path)] + argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path.parent / "B0.npz") in err and found in err, err


def test_coo_npz_checked_and_read(tmp_path):
    from infsup_contact.systems.readers import SystemFileError, read_matrix

    B = sp.coo_matrix(_level(8, "ok")[2])
    sp.save_npz(tmp_path / "ok.npz", B, compressed=False)
    assert np.array_equal(read_matrix(tmp_path / "ok.npz").toarray(), B.toarray())
    np.savez(tmp_path / "bad.npz", format=np.array("coo"), shape=np.array(B.shape), data=B.data,
             row=B.row, col=B.col + 100)
    with pytest.raises(SystemFileError, match=r"bad.npz: column index 1\d\d outside 0..15"):
        read_matrix(tmp_path / "bad.npz")


def test_harwell_boeing_index_out_of_range(tmp_path):
    """A row index beyond the declared rows was read silently (an entry lost, or a crash)."""
    import scipy.io

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    B = sp.csc_matrix(_level(8, "ok")[2])
    scipy.io.hb_write(str(tmp_path / "B.rua"), B)
    text = (tmp_path / "B.rua").read_text()
    assert "\n 1 2 3 4\n" in text
    (tmp_path / "B.rua").write_text(text.replace("\n 1 2 3 4\n", "\n 1 2 3 9\n"))
    with pytest.raises(SystemFileError, match=r"B.rua: CSC: row index 8 outside 0..3"):
        read_matrix(tmp_path / "B.rua")


# ------------------------------------------------------------------ 3. files cut short, keys given twice, names

def test_matrixmarket_cut_inside_its_last_number_is_refused(tmp_path, capsys):
    """Before: 2.5000000000000000e-0 (the file cut inside 2.5000000000000000e-01) read as 2.5."""
    import gzip

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    text = ("%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0000000000000000e+00\n"
            "2 2 2.5000000000000000e-01\n")
    (tmp_path / "full.mtx").write_text(text)
    assert read_matrix(tmp_path / "full.mtx").toarray()[1, 1] == 0.25
    for name, raw in (("cut.mtx", text[:-2].encode()), ("cut.mtx.gz", gzip.compress(text[:-2].encode()))):
        (tmp_path / name).write_bytes(raw)
        with pytest.raises(SystemFileError, match=rf"{name}: MatrixMarket: the last line does not end with a newline"):
            read_matrix(tmp_path / name)
    path = _write(tmp_path, "ok")
    (path.parent / "B1.mtx").write_bytes((path.parent / "B1.mtx").read_bytes()[:-2])
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "B1.mtx: MatrixMarket: the last line" in err


@pytest.mark.parametrize("edit, found", [
    (lambda t: t.replace("norm: given\n", "norm: given\nnorm: L2\n"),
     "norm (line 3): key 'norm' given twice (lines 2 and 3"),
    (lambda t: t.replace("G: G1.mtx}", "G: G1.mtx, h: 0.1}"), "levels[1].h (line 5): key 'h' given twice"),
])
def test_a_key_given_twice_is_refused(tmp_path, capsys, edit, found):
    """Before: the second value silently (norm: L2 gave the L2 verdict, h: 0.1 another slope)."""
    path = _write(tmp_path, "ok")
    path.write_text(edit(path.read_text()))
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and found in err, err


@pytest.mark.parametrize("name", ['"ok\\rSTABLE"', '"two\\nlines"', '"tab\\there"', '"esc\\e[2J"', '"ls\\u2028x"'])
def test_a_control_character_in_name_is_refused(tmp_path, capsys, name):
    """Before: a CR or LF in ``name`` split the CSV row (line-oriented tools saw two rows)."""
    path = _write(tmp_path, "ok")
    path.write_text(path.read_text().replace("name: ok", f"name: {name}"))
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "name: the control character" in err, err
    path.write_text(path.read_text().replace(f"name: {name}", "name: ok").replace("B0.mtx", '"B\\r0.mtx"'))
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    assert "levels[0].B: the control character '\\r'" in capsys.readouterr().err


# ------------------------------------------------------------------ 4. bounded memory from small files

LAUGHS = "".join(f" &{c} [{','.join([f'*{p}'] * 9) if p else ','.join(['lol'] * 9)}],\n"
                 for p, c in zip(["", *"abcdefg"], "abcdefgh"))


def test_billion_laughs_manifest_is_refused_at_once(tmp_path, capsys):
    """Before: a 400-byte manifest took 10 s and 2.5 GB, then a MemoryError traceback."""
    import time

    path = _write(tmp_path, "ok")
    path.write_text(path.read_text().replace("norm: given\n", f"norm: [\n{LAUGHS} [*h,*h,*h,*h,*h,*h,*h,*h,*h]]\n"))
    t0 = time.perf_counter()
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    assert time.perf_counter() - t0 < 5
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "aliases expand to more than 100,000" in err, err


def test_billion_laughs_config_is_refused_at_once(tmp_path):
    """The workflow's config files go through the same loader (config.strict_yaml.check_config_file, run by
    workflow/rules/common.smk); before, the check itself walked the 9^9 values (> 60 s)."""
    from infsup_contact.config.checks import ConfigError
    from infsup_contact.config.strict_yaml import check_config_file
    from infsup_contact.yaml_limits import load

    path = tmp_path / "config.yaml"
    path.write_text(f"x: [\n{LAUGHS} [*h,*h,*h,*h,*h,*h,*h,*h,*h]]\n")
    with pytest.raises(ConfigError, match="aliases expand to more than"):
        check_config_file(path)
    assert load("a: &x [1, 2]\nb: *x\nc: {<<: {p: 1}, p: 2}\n") == {"a": [1, 2], "b": [1, 2], "c": {"p": 2}}
    path.write_text("a: &x [1, *x]\n")
    with pytest.raises(ConfigError, match="recursive alias"):
        check_config_file(path)


def _little_memory(monkeypatch, mib=64):
    from infsup_contact import resources

    monkeypatch.setattr(resources, "available_bytes", lambda *a, **k: float(mib * 2 ** 20))


def test_mtx_gz_declaring_more_than_memory_is_refused_before_its_body(tmp_path, monkeypatch):
    """Before: an 8.7 MB .mtx.gz declaring 6e8 entries took scipy to a 2.24 GiB allocation per
    array (past 4 GB on --dry-run); now its size line is checked against MemAvailable."""
    import gzip

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    _little_memory(monkeypatch)
    with gzip.open(tmp_path / "A.mtx.gz", "wb") as fh:
        fh.write(b"%%MatrixMarket matrix coordinate real general\n% a comment\n1000000 1000000 600000000\n")
        fh.write(b"1 1 1\n" * 100000)
    with pytest.raises(SystemFileError, match=r"A.mtx.gz: its header declares a 1000000 x 1000000 matrix with "
                       r"600000000 entries: reading it needs ~\d+(\.\d+)? GiB, 64 MiB available"):
        read_matrix(tmp_path / "A.mtx.gz")


def test_mtx_declaring_more_entries_than_its_bytes_is_refused(tmp_path):
    from infsup_contact.systems.readers import SystemFileError, read_matrix

    (tmp_path / "A.mtx").write_text("%%MatrixMarket matrix coordinate real general\n10 10 3000\n1 1 1.0\n")
    with pytest.raises(SystemFileError, match="declares 3000 entries, but the .* bytes hold at most"):
        read_matrix(tmp_path / "A.mtx")


def test_npz_zip_bomb_is_refused_from_its_declared_sizes(tmp_path, monkeypatch):
    """A compressed .npz of zeros declares its arrays' shapes; they are checked before a byte of
    the body is inflated (before: a 12 MB .npz took --dry-run past 4 GB)."""
    from infsup_contact.systems.readers import SystemFileError, read_matrix

    _little_memory(monkeypatch)
    np.savez_compressed(tmp_path / "A.npz", A=np.zeros((3000, 3000)))
    assert (tmp_path / "A.npz").stat().st_size < 200_000
    with pytest.raises(SystemFileError, match=r"A.npz: its arrays \{'A': \(3000, 3000\)\} declare 68.7 MiB"):
        read_matrix(tmp_path / "A.npz")
    B = sp.random(3000, 3000, density=0.3, random_state=1, format="csr")
    sp.save_npz(tmp_path / "B.npz", B)
    with pytest.raises(SystemFileError, match=r"B.npz: its arrays .* declare"):
        read_matrix(tmp_path / "B.npz")


def test_npy_and_npz_headers_declaring_more_than_they_hold(tmp_path):
    from numpy.lib import format as npformat

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    with open(tmp_path / "A.npy", "wb") as fh:
        npformat.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (10 ** 6, 10 ** 6)})
        fh.write(b"\0" * 800)
    with pytest.raises(SystemFileError, match=r"A.npy: the header declares shape \(1000000, 1000000\) of float64 "
                       r"\(8000000000000 bytes\), the file holds 800"):
        read_matrix(tmp_path / "A.npy")
    import zipfile

    with zipfile.ZipFile(tmp_path / "A.npz", "w") as zf, zf.open("A.npy", "w") as fh:
        npformat.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (10 ** 5, 10 ** 5)})
        fh.write(b"\0" * 800)
    with pytest.raises(SystemFileError, match=r"A.npz: array 'A': the header declares shape \(100000, 100000\)"):
        read_matrix(tmp_path / "A.npz")


def test_petsc_header_is_checked_before_the_body_is_read(tmp_path, monkeypatch):
    """Only the matrix's bytes are read (a file may hold further objects; before, the whole file
    was read first); a header declaring more than the file holds, or than the memory, is refused."""
    import tracemalloc

    from infsup_contact.systems.hb_petsc import petsc_binary_bytes
    from infsup_contact.systems.readers import SystemFileError, read_matrix

    M = sp.random(50, 40, density=0.2, random_state=2, format="csr")
    (tmp_path / "M.petsc").write_bytes(petsc_binary_bytes(M) + b"\0" * (40 * 2 ** 20))
    tracemalloc.start()
    got = read_matrix(tmp_path / "M.petsc")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert np.array_equal(got.toarray(), M.toarray()) and peak < 4 * 2 ** 20
    from infsup_contact.systems.hb_petsc import MAT_FILE_CLASSID

    (tmp_path / "D.petsc").write_bytes(np.array([MAT_FILE_CLASSID, 10 ** 5, 10 ** 5, -1], ">i4").tobytes()
                                       + b"\0" * 64)
    with pytest.raises(SystemFileError, match=r"D.petsc: PETSc binary: truncated: header says 100000 x 100000 with "
                       r"dense entries \(80000000016 bytes\), the file has 80"):
        read_matrix(tmp_path / "D.petsc")
    _little_memory(monkeypatch, 0.01)
    with pytest.raises(SystemFileError, match=r"M.petsc: its header declares a 50 x 40 matrix with 400 nonzeros"):
        read_matrix(tmp_path / "M.petsc")


# ------------------------------------------------------------------ 5. export does not overwrite another system

def test_export_into_a_directory_holding_another_system(tmp_path, capsys):
    """Before: a second export overwrote levels.yaml and the matrices without a word (and left the
    first export's finer levels next to it)."""
    out = tmp_path / "sys"
    base = ["export", "--case", "T3", "--k", "1", "--out", str(out)]
    assert main(base + ["--N", "2", "4", "8"]) == 0
    manifest = (out / "levels.yaml").read_text()
    capsys.readouterr()
    for extra in (["--dry-run"], []):
        assert main(base + ["--N", "2", "4"] + extra) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"it would overwrite {out / 'levels.yaml'} and 6 more file(s)" in err
        assert "--force" in err
    assert (out / "levels.yaml").read_text() == manifest
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "mine.txt").write_text("x")
    assert main(["export", "--case", "T3", "--k", "1", "--N", "2", "--out", str(tmp_path / "notes")]) == 2
    assert f"it holds {tmp_path / 'notes' / 'mine.txt'}" in capsys.readouterr().err
    assert main(base + ["--N", "2", "4", "--force"]) == 0
    err = capsys.readouterr().err
    left = sorted(p.name for p in out.iterdir() if p.name.startswith(("A2", "B2", "G2", "level2_")))
    assert len(left) > 3  # the level's matrices and the side files of its description
    assert f"{len(left)} file(s) not written by this export left" in err and "A2.mtx, B2.mtx, G2.mtx" in err
    assert (out / "levels.yaml").read_text() != manifest
    (tmp_path / "empty").mkdir()
    assert main(["export", "--case", "T3", "--k", "1", "--N", "2", "--out", str(tmp_path / "empty")]) == 0


def test_harwell_boeing_header_declaring_more_than_the_file(tmp_path, monkeypatch):
    import scipy.io

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    scipy.io.hb_write(str(tmp_path / "B.rua"), sp.csc_matrix(_level(8, "ok")[2]))
    lines = (tmp_path / "B.rua").read_text().split("\n")
    assert lines[2].split()[1:4] == ["4", "16", "4"]
    lines[2] = lines[2][:42] + f"{10 ** 9:14d}" + lines[2][56:]
    (tmp_path / "B.rua").write_text("\n".join(lines))
    with pytest.raises(SystemFileError, match=r"B.rua: Harwell-Boeing: the header declares 1000000000 nonzeros"):
        read_matrix(tmp_path / "B.rua")
    scipy.io.hb_write(str(tmp_path / "B.rua"), sp.csc_matrix(_level(8, "ok")[2]))
    _little_memory(monkeypatch, 1e-4)
    with pytest.raises(SystemFileError, match=r"B.rua: its header declares a 4 x 16 matrix with 4 nonzeros"):
        read_matrix(tmp_path / "B.rua")


def test_constrained_npy_with_a_forged_header(tmp_path, capsys):
    from numpy.lib import format as npformat

    path = _write(tmp_path, "ok")
    with open(path.parent / "fixed.npy", "wb") as fh:
        npformat.write_array_header_1_0(fh, {"descr": "<i8", "fortran_order": False, "shape": (10 ** 12,)})
        fh.write(b"\\0" * 16)
    path.write_text(path.read_text().replace("G: G0.mtx}", "G: G0.mtx, constrained: fixed.npy}"))
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "fixed.npy: the header declares shape (1000000000000,)" in err, err


def test_a_huge_manifest_is_not_read(tmp_path):
    from infsup_contact.systems.readers import SystemFileError

    path = tmp_path / "levels.yaml"
    with open(path, "wb") as fh:
        fh.write(b"name: big\n# " + b"x" * (2 << 20) + b"\n")
    with pytest.raises(SystemFileError, match=r"levels.yaml: 2097165 bytes: a manifest lists a few levels"):
        load_manifest(path)


def test_mtx_gz_longer_than_its_header_declares_stops_early(tmp_path):
    """A small .mtx.gz inflating to far more lines than its size line declares is refused after
    at most MTX_SLACK + MTX_LINE_MAX·entries bytes, not streamed to its end."""
    import gzip

    from infsup_contact.systems.readers import SystemFileError, read_matrix

    with gzip.open(tmp_path / "A.mtx.gz", "wb") as fh:
        fh.write(b"%%MatrixMarket matrix coordinate real general\n10 10 10\n")
        fh.write(b"1 1 1\n" * (1 << 20))
    with pytest.raises(SystemFileError, match=r"A.mtx.gz: MatrixMarket: more than 1051136 bytes \(decompressed\) "
                       r"for the 10 entries"):
        read_matrix(tmp_path / "A.mtx.gz")
