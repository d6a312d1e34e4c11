"""The two binary-era formats of foreign systems: the Harwell-Boeing header checked against the
memory before ``scipy.io.hb_read`` reads it, and the PETSc binary matrix read and written without
PETSc (:func:`~.readers.read_matrix` dispatches here by extension).

The PETSc binary format (PETSc manual, ``MatLoad``/``MatView`` with a binary viewer; the
reference implementation is PETSc's ``lib/petsc/bin/PetscBinaryIO.py``), as read by
:func:`read_petsc_binary`: everything big-endian;

* a sparse matrix: ``int32 MAT_FILE_CLASSID = 1211216``, ``int32 M`` (rows),
  ``int32 N`` (columns), ``int32 nz`` (total nonzeros), ``int32 row_lengths[M]``,
  ``int32 column_indices[nz]`` (0-based, row by row), ``float64 values[nz]``;
* a PETSc built with ``--with-64-bit-indices`` writes every integer as ``int64``
  (recognized: the first 8 bytes are the class id as ``int64``);
* a dense matrix (``MatView`` of ``MATDENSE``) has ``nz = -1`` and then ``M·N`` ``float64``
  values row by row;
* a file may hold further objects after the matrix; they are ignored (the first object must
  be a matrix). Single precision and complex scalars are not read (refused by size checks).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from .file_checks import HEADER_LINE_MAX, SystemFileError, check_read_memory

MAT_FILE_CLASSID = 1211216
"""PETSc's class id of a matrix in a binary file."""
DENSE_NZ = -1
"""``nz`` of a dense matrix in a PETSc binary file (MATRIX_BINARY_FORMAT_DENSE)."""


def check_hb_header(path):
    """The Harwell-Boeing sizes (line 3: type, rows, columns, nonzeros) against the memory."""
    with open(path, "rb") as fh:
        lines = [fh.readline(HEADER_LINE_MAX) for _ in range(3)]
    try:
        rows, cols, nnz = (int(t) for t in lines[2][14:56].split()[:3])
    except (ValueError, IndexError):
        return  # hb_read names what is wrong
    if min(rows, cols, nnz) < 0:
        raise SystemFileError(path, f"Harwell-Boeing: negative size {rows} x {cols}, {nnz} nonzeros in the header")
    if 4 * nnz > path.stat().st_size:  # each nonzero needs a row index and a value, >= 2 characters each
        raise SystemFileError(path, f"Harwell-Boeing: the header declares {nnz} nonzeros, the file's "
                              f"{path.stat().st_size} bytes cannot hold them")
    check_read_memory(path, rows, cols, nnz, f"{nnz} nonzeros")


def read_petsc(path):
    """The matrix of a PETSc binary file: by petsc4py when importable, else :func:`read_petsc_binary`."""
    try:
        from petsc4py import PETSc  # noqa: F401
    except ImportError:
        return read_petsc_binary(path)
    return _read_petsc4py(path)


def _read_petsc4py(path):  # pragma: no cover - petsc4py is not in the lock
    from petsc4py import PETSc

    viewer = PETSc.Viewer().createBinary(str(path), "r")
    mat = PETSc.Mat().load(viewer)
    if mat.getType() in ("seqdense", "mpidense", "dense"):
        return np.array(mat.getDenseArray())
    indptr, indices, data = mat.getValuesCSR()
    return sp.csr_matrix((data, indices, indptr), shape=mat.getSize())


def read_petsc_binary(path):
    """A matrix from a PETSc binary file, without PETSc (the layout: module docstring).

    Returns
    -------
    scipy.sparse.csr_matrix or ndarray
        CSR for a sparse matrix, a dense array for ``nz = -1``.
    """
    path = Path(path)
    with open(path, "rb") as fh:
        raw = fh.read(32)
    if len(raw) < 16:
        raise SystemFileError(path, f"PETSc binary: {len(raw)} bytes, shorter than a matrix header (16)")
    first32 = int(np.frombuffer(raw, ">i4", 1)[0])
    if first32 == MAT_FILE_CLASSID:
        itype = np.dtype(">i4")
    elif len(raw) >= 32 and int(np.frombuffer(raw, ">i8", 1)[0]) == MAT_FILE_CLASSID:
        itype = np.dtype(">i8")
    else:
        raise SystemFileError(path, f"PETSc binary: first integer is {first32}, not the matrix class id "
                              f"{MAT_FILE_CLASSID} (not a PETSc matrix, or not big-endian)")
    isz = itype.itemsize
    m, n, nz = (int(v) for v in np.frombuffer(raw, itype, 3, offset=isz))
    pos = 4 * isz
    if m < 0 or n < 0:
        raise SystemFileError(path, f"PETSc binary: negative size {m} x {n} in the header")
    size = path.stat().st_size
    need = pos + (8 * m * n if nz == DENSE_NZ else isz * (m + max(nz, 0)) + 8 * max(nz, 0))
    if nz < DENSE_NZ or size < need:  # checked before the body is read (a header can declare anything)
        raise SystemFileError(path, f"PETSc binary: truncated: header says {m} x {n} with "
                              f"{'dense entries' if nz == DENSE_NZ else f'{nz} nonzeros'} ({need} bytes), "
                              f"the file has {size}")
    check_read_memory(path, m, n, None if nz == DENSE_NZ else nz,
                      "dense entries" if nz == DENSE_NZ else f"{nz} nonzeros")
    with open(path, "rb") as fh:
        raw = fh.read(need)  # the matrix only: further objects in the file are not read
    if nz == DENSE_NZ:
        need = pos + 8 * m * n
        if len(raw) < need:
            raise SystemFileError(path, f"PETSc binary: truncated: a dense {m} x {n} matrix needs {need} bytes, "
                                  f"the file has {len(raw)}")
        return np.frombuffer(raw, ">f8", m * n, offset=pos).reshape(m, n).astype(float)
    need = pos + isz * (m + nz) + 8 * nz
    if nz < 0 or len(raw) < need:
        raise SystemFileError(path, f"PETSc binary: truncated: header says {m} x {n} with {nz} nonzeros "
                              f"({need} bytes), the file has {len(raw)}")
    lengths = np.frombuffer(raw, itype, m, offset=pos).astype(np.int64)
    if (lengths < 0).any() or lengths.sum() != nz:
        raise SystemFileError(path, f"PETSc binary: row lengths sum to {int(lengths.sum())}, header says {nz} nonzeros")
    cols = np.frombuffer(raw, itype, nz, offset=pos + isz * m).astype(np.int64)
    if nz and (cols.min() < 0 or cols.max() >= n):
        raise SystemFileError(path, f"PETSc binary: column index {int(cols.max() if cols.max() >= n else cols.min())} "
                              f"outside 0..{n - 1}")
    vals = np.frombuffer(raw, ">f8", nz, offset=pos + isz * (m + nz)).astype(float)
    indptr = np.concatenate([[0], np.cumsum(lengths)])
    return sp.csr_matrix((vals, cols, indptr), shape=(m, n))


def petsc_binary_bytes(mat) -> bytes:
    """The bytes of ``mat`` (sparse or dense, written as sparse AIJ) in PETSc's binary layout
    with 32-bit indices; :func:`infsup_contact.io.write_bytes_atomic` writes them."""
    A = sp.csr_matrix(mat, dtype=float)
    A.sort_indices()
    m, n = A.shape
    if max(m, n, A.nnz) >= 2 ** 31:
        raise ValueError("matrix too large for 32-bit PETSc indices")
    header = np.array([MAT_FILE_CLASSID, m, n, A.nnz], ">i4").tobytes()
    return (header + np.diff(A.indptr).astype(">i4").tobytes() + A.indices.astype(">i4").tobytes()
            + A.data.astype(">f8").tobytes())
