"""Running FreeFem++ and reading what it writes (numpy and scipy only, like the contract).

``ofstream << matrix`` writes FreeFEM's sparse text format: comment lines (``#``), one line
``n m nnz half fortran state ...`` and then one ``i j a_ij`` line per stored entry, 0-based
unless ``fortran`` is 1, the lower triangle only when ``half`` is 1. ``ofstream << array``
writes the length and then the values (five to a line). Both are read here and converted by
the exporter to MatrixMarket: the suite reads one format, not FreeFEM's.
"""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import scipy.sparse as sp

LOADPATH = "/usr/lib/freefem++"
"""Where Debian's ``libfreefem++`` puts the plugins (``load "msh3"``). Debian's
/etc/freefem++.pref names /usr/lib/ff++/4.9/lib, which the package does not create, so every
script that loads a plugin fails there; ``FF_LOADPATH`` overrides it."""


class FreeFemError(Exception):
    """FreeFem++ missing, failing, or writing something this reader does not know."""


def freefem_binary() -> str:
    """The ``FreeFem++`` on PATH (Debian's ``freefem++``)."""
    exe = shutil.which("FreeFem++")
    if exe is None:
        raise FreeFemError("FreeFem++ not found on PATH: run `make producers-freefem` (Debian freefem++, as root)")
    return exe


def run_script(script: Path, cwd: Path, timeout: float = 600.0) -> None:
    """Run ``FreeFem++ -nw -v 0 script`` in ``cwd`` (no graphics; its output captured, never on
    our stdout); :class:`FreeFemError` with its last line when it fails."""
    env = dict(os.environ, FF_LOADPATH=os.environ.get("FF_LOADPATH", LOADPATH))
    done = subprocess.run([freefem_binary(), "-nw", "-v", "0", str(script)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        tail = [ln.strip() for ln in (done.stdout + done.stderr).splitlines() if ln.strip()]
        raise FreeFemError(f"FreeFem++ {script.name} exited {done.returncode}: {' | '.join(tail[-3:])}")


def read_matrix(path: Path) -> sp.csr_matrix:
    """A matrix FreeFEM wrote with ``ofstream << matrix``, in either of its two text layouts:
    ``HashMatrix`` (header ``n m nnz half fortran state``, 0-based unless ``fortran``) or
    ``Sparse Matrix (Morse)`` (a matrix built with ``solver=``: header ``n m symmetric nnz``,
    1-based); a half-stored (symmetric) matrix is completed from its stored triangle."""
    text = Path(path).read_text()
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    head = lines[0].split() if lines else []
    if len(head) < 4:
        raise FreeFemError(f"{path}: no FreeFEM matrix header (found {lines[:1]!r:.60})")
    if "(Morse)" in text.split("\n", 1)[0]:
        n, m, half, nnz = (int(v) for v in head[:4])
        base = 1
    else:
        n, m, nnz, half, base = (int(v) for v in head[:5])
    data = np.array([ln.split() for ln in lines[1:]], dtype=float).reshape(-1, 3)
    if len(data) != nnz:
        raise FreeFemError(f"{path}: header declares {nnz} entries, the file holds {len(data)}")
    i, j = data[:, 0].astype(np.int64) - base, data[:, 1].astype(np.int64) - base
    if len(data) and (i.min() < 0 or j.min() < 0 or i.max() >= n or j.max() >= m):
        raise FreeFemError(f"{path}: an index outside {n} x {m}")
    mat = sp.coo_matrix((data[:, 2], (i, j)), shape=(n, m)).tocsr()
    if half:  # one triangle of a symmetric matrix stored: add the other
        mat = (mat + mat.T - sp.diags(mat.diagonal())).tocsr()
    return mat


def read_arrays(path: Path) -> list:
    """The arrays ``ofstream << a[] << b[] ...`` wrote, in order (each: its length, then values)."""
    tokens = Path(path).read_text().split()
    out, i = [], 0
    while i < len(tokens):
        n = int(tokens[i])
        out.append(np.array(tokens[i + 1:i + 1 + n], dtype=float))
        if len(out[-1]) != n:
            raise FreeFemError(f"{path}: an array of {n} values is cut short")
        i += n + 1
    return out


def version() -> str:
    """FreeFEM's version as the binary states it (``FreeFem++ - version 4.9 ...``); Debian's
    freefem++ 4.11+dfsg1-3 reports 4.9."""
    done = subprocess.run([freefem_binary()], capture_output=True, text=True, timeout=60)
    for word_list in ((done.stdout + done.stderr).split("version", 1)[1:]):
        return word_list.split()[0]
    raise FreeFemError("FreeFem++ printed no version")
