"""Read one matrix file of a foreign system, by its extension, with the library made for it.

========================  ======================================================
extension                 reader
========================  ======================================================
``.mtx``, ``.mtx.gz``,    ``scipy.io.mmread`` (MatrixMarket coordinate or array;
``.mm``, ``.mm.gz``       ``.mm`` is Kratos's name for it)
``.npz``                  ``scipy.sparse.load_npz``; else ``numpy.load`` of an
                          archive holding exactly one array (dense)
``.npy``                  ``numpy.load`` (dense)
``.hb``, ``.rb``,         ``scipy.io.hb_read`` (Harwell-Boeing, real assembled)
``.rua``, ``.rsa``
``.petsc``, ``.bin``,     ``petsc4py`` when importable, else :func:`read_petsc_binary`
``.dat``
========================  ======================================================

Every failure — a missing file, a truncated one, a file in another format than its name
says — is a :class:`SystemFileError`: one line naming the file and what was found. The
Harwell-Boeing header check and the PETSc binary layout are :mod:`.hb_petsc`'s; what every format
passes before its body is read (the memory, the index arrays) is :mod:`.file_checks`'s.
"""
from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from .file_checks import (HEADER_LINE_MAX, READ_COPIES, SystemFileError, check_compressed, check_coordinates,
                          check_read_memory, check_sparse)
from .hb_petsc import check_hb_header, read_petsc

FORMATS = {".mtx": "MatrixMarket", ".mtx.gz": "MatrixMarket (gzip)", ".mm": "MatrixMarket",
           ".mm.gz": "MatrixMarket (gzip)", ".npz": "scipy/numpy .npz",
           ".npy": "numpy .npy", ".hb": "Harwell-Boeing", ".rb": "Harwell-Boeing",
           ".rua": "Harwell-Boeing", ".rsa": "Harwell-Boeing", ".petsc": "PETSc binary",
           ".bin": "PETSc binary", ".dat": "PETSc binary"}
"""Readable extensions and the format each one means."""


def extension(path) -> str:
    """The format-deciding extension of ``path`` (``.mtx.gz`` and ``.mm.gz`` count as one)."""
    name = Path(path).name.lower()
    for gz in (".mtx.gz", ".mm.gz"):
        if name.endswith(gz):
            return gz
    return Path(name).suffix


def read_matrix(path):
    """The matrix in ``path`` as a scipy CSR matrix or a 2-D float ndarray.

    Raises
    ------
    SystemFileError
        The file is missing, empty, of an unknown extension, truncated, or not in the
        format its extension names.
    """
    path = Path(path)
    ext = extension(path)
    if ext not in FORMATS:
        raise SystemFileError(path, f"unknown extension {ext or '(none)'!r} (readable: "
                              f"{', '.join(FORMATS)})")
    if not path.is_file():
        raise SystemFileError(path, "no such file")
    if path.stat().st_size == 0:
        raise SystemFileError(path, f"empty file (expected {FORMATS[ext]})")
    try:
        if FORMATS[ext].startswith("MatrixMarket"):
            mat = _read_mtx(path, ext)
        elif ext == ".npz":
            mat = _read_npz(path)
        elif ext == ".npy":
            mat = _read_npy(path)
        elif FORMATS[ext] == "Harwell-Boeing":
            import scipy.io

            check_hb_header(path)
            mat = scipy.io.hb_read(str(path))
        else:
            mat = read_petsc(path)
    except SystemFileError:
        raise
    except Exception as err:  # every library error becomes one line naming the file
        reason = " ".join(str(err).split())[:160] or type(err).__name__
        raise SystemFileError(path, f"not a readable {FORMATS[ext]} file ({type(err).__name__}: {reason})") from None
    try:
        return _as_float_matrix(path, mat)
    except MemoryError:
        raise SystemFileError(path, f"not enough memory to hold it as a float matrix ({_describe(mat)})") from None


def _describe(mat) -> str:
    shape = " x ".join(map(str, getattr(mat, "shape", ())))
    return f"{shape}, {mat.nnz} nonzeros" if sp.issparse(mat) else f"{shape} dense"


def _as_float_matrix(path, mat):
    if sp.issparse(mat):
        check_sparse(path, mat)
        mat = sp.csr_matrix(mat)
    else:
        mat = np.asarray(mat)
        if mat.ndim != 2:
            raise SystemFileError(path, f"holds a {mat.ndim}-D array of shape {mat.shape}, not a matrix")
    if not np.issubdtype(mat.dtype, np.number) or np.issubdtype(mat.dtype, np.complexfloating):
        raise SystemFileError(path, f"holds {mat.dtype} entries (expected real numbers)")
    return mat.astype(float, copy=False)


def _read_mtx(path, ext):
    import scipy.io

    with (gzip.open(path, "rb") if ext.endswith(".gz") else open(path, "rb")) as fh:
        head = fh.read(15)
    if not head.startswith(b"%%MatrixMarket"):
        raise SystemFileError(path, f"does not start with the MatrixMarket banner '%%MatrixMarket' "
                              f"(found {head[:15]!r})")
    rows, cols, entries, dense, pattern = _mtx_header(path, ext)
    check_read_memory(path, rows, cols, None if dense else entries, f"{entries} entries")
    longest = MTX_SLACK + MTX_LINE_MAX * entries
    last, size = _last_byte(path, ext, longest)
    if size > longest:
        raise SystemFileError(path, f"MatrixMarket: more than {longest} bytes{' (decompressed)' if ext.endswith('.gz') else ''} "
                              f"for the {entries} entries its header declares (at most {MTX_LINE_MAX} bytes a line)")
    if last != b"\n":
        raise SystemFileError(path, "MatrixMarket: the last line does not end with a newline (a file cut "
                              "short, possibly inside its last number: write it again)")
    shortest = 2 if dense else (4 if pattern else 6)  # "v\n", "i j\n", "i j v\n"
    if entries * shortest > size:
        raise SystemFileError(path, f"MatrixMarket: the header declares {entries} entries, but the "
                              f"{size} bytes{' (decompressed)' if ext.endswith('.gz') else ''} hold at most "
                              f"{size // shortest}: a file cut short")
    return scipy.io.mmread(str(path))


def _mtx_header(path, ext):
    """(rows, cols, entries, dense, pattern) from the banner and the size line, body unread."""
    with (gzip.open(path, "rb") if ext.endswith(".gz") else open(path, "rb")) as fh:
        banner = fh.readline(HEADER_LINE_MAX).decode("ascii", "replace").lower().split()
        while True:
            line = fh.readline(HEADER_LINE_MAX)
            if not line:
                raise SystemFileError(path, "MatrixMarket: no size line after the banner")
            while not line.endswith(b"\n") and line.startswith(b"%"):  # a long comment: skip it
                more = fh.readline(HEADER_LINE_MAX)
                if not more:
                    break
                line = line[:1] + more
            if line.strip() and not line.startswith(b"%"):
                break
    if len(banner) < 5 or banner[1] != "matrix" or banner[2] not in ("coordinate", "array"):
        raise SystemFileError(path, f"MatrixMarket: banner {' '.join(banner)[:80]!r} is not "
                              "'%%MatrixMarket matrix coordinate|array <field> <symmetry>'")
    dense = banner[2] == "array"
    try:
        sizes = [int(t) for t in line.split()]
    except ValueError:
        sizes = []
    if len(sizes) != (2 if dense else 3) or min(sizes) < 0:
        raise SystemFileError(path, f"MatrixMarket: size line {line[:80].decode('ascii', 'replace').strip()!r} is "
                              f"not {'rows cols' if dense else 'rows cols entries'} (integers >= 0)")
    rows, cols = sizes[:2]
    entries = rows * cols if dense else sizes[2]
    if dense and banner[4] != "general":  # symmetric: the lower triangle only
        entries = rows * (rows + 1) // 2 if banner[4] != "skew-symmetric" else rows * (rows - 1) // 2
    return rows, cols, entries, dense, banner[3] == "pattern"


MTX_LINE_MAX = 256
"""Longest MatrixMarket entry line accepted (two indices and a 17-digit value take < 64 bytes)."""
MTX_SLACK = 1 << 20
"""Bytes allowed for the banner and comments besides the entries."""


def _last_byte(path, ext, stop=None):
    """(the last byte, the size) of the (decompressed) file; a .mtx.gz is streamed (constant
    memory), and only until ``stop`` bytes (its size then just exceeds ``stop``)."""
    if not ext.endswith(".gz"):
        with open(path, "rb") as fh:
            fh.seek(-1, 2)
            return fh.read(1), fh.tell()
    last, size = b"", 0
    with gzip.open(path, "rb") as fh:
        while chunk := fh.read(1 << 20):
            last, size = chunk[-1:], size + len(chunk)
            if stop is not None and size > stop:
                break
    return last, size


def _npy_header(fh):
    """(shape, dtype) of an .npy stream, its body unread."""
    from numpy.lib import format as npformat

    version = npformat.read_magic(fh)
    reader = npformat.read_array_header_1_0 if version == (1, 0) else npformat.read_array_header_2_0
    shape, _, dtype = reader(fh, max_header_size=10000)
    return tuple(int(d) for d in shape), dtype


def _check_npy(path, shape, dtype, stored: int, member: str = ""):
    """An array's declared bytes against what the file (or zip member) holds, and the memory."""
    where = f"array {member!r}: " if member else ""
    if dtype.hasobject:
        raise SystemFileError(path, f"{where}holds Python objects (dtype {dtype}), not numbers")
    count = int(np.prod(shape, dtype=object)) if shape else 1
    if count * dtype.itemsize > stored:
        raise SystemFileError(path, f"{where}the header declares shape {shape} of {dtype} ({count * dtype.itemsize} "
                              f"bytes), the file holds {stored}: a file cut short or forged")
    return count


def check_npy_file(path) -> tuple:
    """The shape an ``.npy`` file declares, checked against its bytes and the memory before
    its body is read (:class:`SystemFileError`); any other reading error is the caller's."""
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as fh:
        try:
            shape, dtype = _npy_header(fh)
        except ValueError as err:
            raise SystemFileError(path, f"not a numpy .npy file ({' '.join(str(err).split())[:120]})") from None
        body = size - fh.tell()
    count = _check_npy(path, shape, dtype, body)
    if len(shape) == 2:
        check_read_memory(path, shape[0], shape[1], None, "dense entries")
    elif count:
        check_read_memory(path, count, 1, None, "dense entries")
    return shape


def _read_npy(path):
    check_npy_file(path)
    return np.load(path, allow_pickle=False)


def _check_npz_members(path):
    """Each member's declared array against its declared size, and the sum against the memory."""
    import zipfile

    total, shapes = 0.0, {}
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            with zf.open(info) as fh:
                shape, dtype = _npy_header(fh)
                stored = info.file_size - fh.tell()
            count = _check_npy(path, shape, dtype, stored, name)
            total += count * max(dtype.itemsize, 8)
            shapes[name] = shape
    from .. import resources

    need, avail = 2.0 * READ_COPIES * total, resources.available_bytes()
    if avail is not None and need > avail:
        raise SystemFileError(path, f"its arrays {shapes} declare {resources.human_bytes(total)}: reading them "
                              f"needs ~{resources.human_bytes(need)}, {resources.human_bytes(avail)} available")


def _read_npz(path):
    with open(path, "rb") as fh:
        if fh.read(4) != b"PK\x03\x04":
            raise SystemFileError(path, "not a zip archive (an .npz is one)")
    _check_npz_members(path)
    with np.load(path, allow_pickle=False) as data:
        keys = set(data.files)
    if {"format", "shape", "data"} <= keys:
        return _sparse_npz(path)
    if len(keys) != 1:
        raise SystemFileError(path, f"an .npz with arrays {sorted(keys)}: expected a scipy.sparse.save_npz "
                              "archive or exactly one dense array")
    with np.load(path, allow_pickle=False) as data:
        return data[next(iter(keys))]


SPARSE_NPZ = {"csr": ("indices", "indptr"), "csc": ("indices", "indptr"), "coo": ("row", "col")}
"""The ``scipy.sparse.save_npz`` layouts read, and their index arrays (bsr and dia are refused)."""


def _sparse_npz(path):
    """A ``scipy.sparse.save_npz`` archive, its index arrays checked before the matrix is built
    (scipy does not check them: an index out of range crashed the process, exit 139)."""
    with np.load(path, allow_pickle=False) as data:
        fmt = data["format"].item()
        fmt = fmt.decode("ascii", "replace") if isinstance(fmt, bytes) else str(fmt)
        if fmt not in SPARSE_NPZ:
            raise SystemFileError(path, f"a scipy.sparse {fmt!r} archive (readable: {', '.join(SPARSE_NPZ)}; "
                                  "save the matrix with .tocsr())")
        missing = [k for k in SPARSE_NPZ[fmt] if k not in data.files]
        if missing:
            raise SystemFileError(path, f"a scipy.sparse {fmt} archive without its {missing[0]!r} array")
        shape = np.asarray(data["shape"])
        arrays = [np.asarray(data[k]) for k in ("data",) + SPARSE_NPZ[fmt]]
    if shape.shape != (2,) or not np.issubdtype(shape.dtype, np.integer) or (shape < 0).any():
        raise SystemFileError(path, f"'shape' is {shape.tolist()!r}, not two integers >= 0")
    m, n = (int(v) for v in shape)
    values, first, second = arrays
    check_read_memory(path, m, n, len(values), f"{len(values)} stored entries")
    if fmt == "coo":
        check_coordinates(path, (m, n), values, first, second)
        return sp.coo_matrix((values, (first, second)), shape=(m, n))
    check_compressed(path, (m, n), values, first, second, rows_major=fmt == "csr")
    return (sp.csr_matrix if fmt == "csr" else sp.csc_matrix)((values, first, second), shape=(m, n))


