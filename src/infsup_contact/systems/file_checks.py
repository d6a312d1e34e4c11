"""What every matrix file of a foreign system passes, whatever its format: the one-line error a
file raises (:class:`SystemFileError`), its header's sizes against the memory before its body is
read (:func:`check_read_memory`), and the index arrays of a sparse matrix before scipy builds it
(:func:`check_compressed`, :func:`check_coordinates`: scipy does not check them).

The readers of each format (:mod:`.readers`: MatrixMarket, ``.npy``/``.npz``, the dispatch by
extension; :mod:`.hb_petsc`: Harwell-Boeing and PETSc binary) import these checks; nothing here
reads a format.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import InputError


class SystemFileError(InputError):
    """A file or manifest entry of a foreign system that cannot be used: one line naming it."""

    def __init__(self, where, problem: str, key: str = "system"):
        self.key, self.allowed, self.got, self.where = key, problem, None, str(where)
        ValueError.__init__(self, f"{where}: {problem}")


HEADER_LINE_MAX = 1 << 16
"""Longest header line read: a MatrixMarket banner or size line (a comment line may be longer: it is
skipped), a Harwell-Boeing header line."""


READ_COPIES = 3.0
"""Copies of a matrix's arrays alive while a file becomes a float CSR matrix (the reader's
arrays, COO → CSR, ``astype``): the factor of :func:`read_bytes`."""


def read_bytes(rows: int, cols: int, nnz) -> float:
    """Bytes to read a rows × cols matrix: dense (``nnz`` None) 8·rows·cols twice (the array and
    its float copy); sparse, (value + two indices) per entry and the index pointers, times
    :data:`READ_COPIES`."""
    if nnz is None:
        return 2.0 * 8.0 * rows * cols
    return READ_COPIES * (24.0 * nnz + 8.0 * (rows + cols + 2))


def check_read_memory(path, rows: int, cols: int, nnz, what: str) -> None:
    """Refuse a file whose header declares more than the available memory can read (before its
    body is read: a small compressed file can declare gigabytes)."""
    from .. import resources

    need = read_bytes(rows, cols, nnz)
    avail = resources.available_bytes()
    if avail is not None and need > avail:
        raise SystemFileError(path, f"its header declares a {rows} x {cols} matrix with {what}: reading it "
                              f"needs ~{resources.human_bytes(need)}, {resources.human_bytes(avail)} available")


def _int_array(path, name, a):
    a = np.asarray(a)
    if a.ndim != 1 or not (np.issubdtype(a.dtype, np.integer) or a.size == 0):
        raise SystemFileError(path, f"'{name}' holds {a.dtype} of shape {a.shape}, not a 1-D integer array")
    return a


def check_coordinates(path, shape, values, row, col):
    """Coordinate (COO) arrays: equal lengths, 0 <= row < m, 0 <= col < n (:class:`SystemFileError`)."""
    row, col = _int_array(path, "row", row), _int_array(path, "col", col)
    if np.ndim(values) != 1 or not len(values) == len(row) == len(col):
        raise SystemFileError(path, f"{np.size(values)} values but {len(row)} row and {len(col)} column indices")
    for name, idx, size in (("row", row, shape[0]), ("column", col, shape[1])):
        if idx.size and (idx.min() < 0 or idx.max() >= size):
            bad = int(idx.min() if idx.min() < 0 else idx.max())
            raise SystemFileError(path, f"{name} index {bad} outside 0..{size - 1} (shape {shape[0]} x {shape[1]})")


def check_compressed(path, shape, values, indices, indptr, rows_major=True):
    """CSR (``rows_major``) or CSC arrays, before scipy sees them: len(indptr) = rows + 1 (CSR),
    indptr from 0, non-decreasing, ending at len(indices) = len(values), 0 <= indices < cols."""
    indices, indptr = _int_array(path, "indices", indices), _int_array(path, "indptr", indptr)
    major, minor = shape if rows_major else shape[::-1]
    kind, what = ("CSR", "column") if rows_major else ("CSC", "row")
    if len(indptr) != major + 1:
        raise SystemFileError(path, f"{kind}: {len(indptr)} index pointers for {major} "
                              f"{'rows' if rows_major else 'columns'} (expected {major + 1})")
    if np.ndim(values) != 1 or len(values) != len(indices):
        raise SystemFileError(path, f"{kind}: {np.size(values)} values but {len(indices)} {what} indices")
    if indptr[0] != 0 or indptr[-1] != len(indices) or (np.diff(indptr) < 0).any():
        raise SystemFileError(path, f"{kind}: index pointers must rise from 0 to {len(indices)} without "
                              f"decreasing (found {int(indptr[0])} .. {int(indptr[-1])}"
                              f"{', decreasing' if (np.diff(indptr) < 0).any() else ''})")
    if indices.size and (indices.min() < 0 or indices.max() >= minor):
        bad = int(indices.min() if indices.min() < 0 else indices.max())
        raise SystemFileError(path, f"{kind}: {what} index {bad} outside 0..{minor - 1} "
                              f"(shape {shape[0]} x {shape[1]})")


def check_sparse(path, mat):
    """The index arrays of a matrix a library built without checking them (Harwell-Boeing)."""
    if isinstance(mat, (sp.csr_matrix, sp.csc_matrix)) or getattr(mat, "format", None) in ("csr", "csc"):
        check_compressed(path, mat.shape, mat.data, mat.indices, mat.indptr, rows_major=mat.format == "csr")
    elif getattr(mat, "format", None) == "coo":
        check_coordinates(path, mat.shape, mat.data, mat.row, mat.col)
