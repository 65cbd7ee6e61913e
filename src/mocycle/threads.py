"""How many threads BLAS and OpenMP may use: one, unless ``MOCYCLE_THREADS`` says otherwise.

mocycle's matrices are small (hundreds of frames, tens of joints): a second BLAS thread costs more in
hand-overs than it saves, and on a busy machine its spinning worker stalls calls of 25 ms for up to a second
(``docs/performance.md`` has the figures).  So BLAS and OpenMP run on one thread by default:

* the command line sets ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS`` ... before numpy
  loads (:func:`pin_environment`; a variable you set yourself is left alone), so no worker thread is even
  started;
* the library's long-running entry points (every task's ``run``, ``find_phase``, ``extract_cycle``,
  ``blend_cycles``, ``stretch_motion``, ``segment``, ``compress`` ...) run under :func:`limited`, a
  threadpoolctl limit, so a script that imported numpy itself gets the same.

``MOCYCLE_THREADS=N`` allows N threads; ``MOCYCLE_THREADS=0`` (or ``auto``) leaves the libraries' own default
(one per core).

The command line also turns off numpy's huge-page advice (``NUMPY_MADVISE_HUGEPAGE=0``, numpy's own switch, read
when numpy loads; set it to 1 yourself to keep numpy's default).  numpy asks the kernel for transparent huge pages
on every array of 4 MB or more; where the kernel cannot find them (every machine this project runs on so far:
``AnonHugePages: 0 kB`` in ``/proc/meminfo``) each such array's first touch costs 3-6 times the system time of
plain pages: 0.75-1.2 s against 0.2 s for a 428 MB array, and 38-44 s against 33-36 s of wall for the loops of
an hour of capture (``docs/performance.md``).
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading

from .errors import MocycleError

__all__ = ["ENV", "HUGEPAGE_VARIABLE", "LIBRARY_VARIABLES", "limit_threads", "limited", "pin_environment", "threads"]

ENV = "MOCYCLE_THREADS"
#: the variables BLAS and OpenMP builds read when they load (and polars, which parses long BVH files)
LIBRARY_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
                     "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS", "POLARS_MAX_THREADS")

_inside = threading.local()


def threads() -> int | None:
    """The thread count for BLAS and OpenMP: ``$MOCYCLE_THREADS``, default 1; ``None`` for the libraries' own
    default (``0`` or ``auto``)."""
    text = os.environ.get(ENV, "").strip().lower()
    if not text:
        return 1
    if text in ("0", "auto"):
        return None
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 0:
        raise MocycleError(f"{ENV} must be a number of threads (1, 2, ...) or 0/auto for the libraries' default; "
                           f"got {text!r}")
    return n


#: numpy's switch for its huge-page advice, read when numpy loads (see the module notes)
HUGEPAGE_VARIABLE = "NUMPY_MADVISE_HUGEPAGE"


def pin_environment() -> None:
    """Set the BLAS/OpenMP thread variables to :func:`threads` and numpy's huge-page advice off where they are
    unset, for the libraries that read them when they load: call before numpy is imported (``mocycle.__main__``
    does, first thing)."""
    n = threads()
    os.environ.setdefault(HUGEPAGE_VARIABLE, "0")
    if n is None:
        return
    for name in LIBRARY_VARIABLES:
        os.environ.setdefault(name, str(n))


@contextlib.contextmanager
def limited():
    """BLAS and OpenMP limited to :func:`threads` within the block (threadpoolctl); nested blocks cost nothing.

    The limit is process-wide, like the libraries' own setting, and restored when the outer block ends.  It
    acts on the libraries loaded when the block starts (looked for again whenever modules were imported
    since), so numpy's and scipy's BLAS are loaded first (the core needs both anyway); an OpenMP library
    loaded later inside the block (scikit-learn's) follows the environment (:func:`pin_environment`), and
    t-SNE limits itself.
    """
    n = threads()
    if n is None or getattr(_inside, "depth", 0):
        yield
        return
    import numpy  # noqa: F401  (load the BLAS libraries so that the limit reaches them)
    import scipy.linalg  # noqa: F401

    _inside.depth = 1
    try:
        with _controller().limit(limits=n):
            yield
    finally:
        _inside.depth = 0


_found: list = [None, -1]  # threadpoolctl's controller and len(sys.modules) when it looked for libraries


def _controller():
    """threadpoolctl's controller of the loaded BLAS/OpenMP libraries, looked for again only when modules were
    imported since the last look (a library comes with a module; the look costs 0.8 ms, a limit 0.02 ms)."""
    from threadpoolctl import ThreadpoolController

    if _found[0] is None or _found[1] != len(sys.modules):
        _found[:] = [ThreadpoolController(), len(sys.modules)]
    return _found[0]


def limit_threads(func):
    """Decorator: run ``func`` :func:`limited` (a long-running library entry point)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with limited():
            return func(*args, **kwargs)

    return wrapper
