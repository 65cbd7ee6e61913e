"""A mocycle command's CPU, split between its first process and its workers (issue 38).

    python benchmarks/cpu_split.py loop SESSION.bvh -o OUT/s.bvh --part all --root motion --workers 2 --json

Runs ``python -m mocycle`` with the arguments given, in this process, and at exit prints to stderr the CPU
seconds (user + system, ``resource.getrusage``) of this process (the read, the cut and its sequential steps,
the feeding of the workers, the output) and of its children (the workers), the wall seconds and the largest
resident sets.  With two cores the wall time is about ``main + workers / 2`` when the workers are kept busy:
a figure that stays readable on a loaded machine, where the wall time does not.
"""

from __future__ import annotations

import atexit
import resource
import runpy
import sys
import time

_START = time.time()


def _report() -> None:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    main_s, workers_s = own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime
    sys.stderr.write(f"CPU main {main_s:.2f} workers {workers_s:.2f} total {main_s + workers_s:.2f} "
                     f"wall {time.time() - _START:.2f} maxrss main {own.ru_maxrss // 1024} MB "
                     f"children {children.ru_maxrss // 1024} MB\n")


if __name__ == "__main__":
    atexit.register(_report)
    sys.argv = ["mocycle", *sys.argv[1:]]
    runpy.run_module("mocycle", run_name="__main__")
