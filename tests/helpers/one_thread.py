"""One MKL thread in the calling thread, as :func:`~infsup_contact.la.threaded.run_concurrently`
gives each task: the serial reference of a bit-for-bit comparison with the concurrent route. An
MKL already started on more threads (``MKL_NUM_THREADS`` unset, as ``make test`` runs) keeps them
whatever the environment says later, and its multi-threaded solves round otherwise."""
from contextlib import contextmanager

from infsup_contact.la import threaded


@contextmanager
def one_mkl_thread():
    for hook in threaded.LOCAL_THREADS_HOOKS:
        hook(1)
    try:
        yield
    finally:
        for hook in threaded.LOCAL_THREADS_HOOKS:
            hook(0)
