"""One BLAS/OpenMP thread by default: in the command line, in the library's entry points and in this suite."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from mocycle import threads
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import write

_CLI_THEN_INFO = r"""
import json, os, sys
sys.argv = ["mocycle"] + json.loads(sys.argv[1])
from mocycle.__main__ import main
try:
    main()
except SystemExit:
    pass
from threadpoolctl import threadpool_info
tasks = len(os.listdir("/proc/self/task")) if os.path.isdir("/proc/self/task") else None
try:
    from numpy._core.multiarray import _get_madvise_hugepage
except ImportError:  # numpy 1.x
    from numpy.core.multiarray import _get_madvise_hugepage
print("\n@@" + json.dumps({"pools": threadpool_info(), "os_threads": tasks, "hugepage": _get_madvise_hugepage(),
                           "env": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")}}))
"""


def cli_pools(args, **env):
    """Run a command through the console script's ``main``, then report the BLAS/OpenMP pools of that process."""
    environ = {k: v for k, v in os.environ.items()
               if k not in threads.LIBRARY_VARIABLES + (threads.ENV, threads.HUGEPAGE_VARIABLE)}
    environ.update(PYTHONPATH=os.pathsep.join(p for p in sys.path if p), **env)
    out = subprocess.run([sys.executable, "-c", _CLI_THEN_INFO, json.dumps([str(a) for a in args])],
                         capture_output=True, text=True, env=environ, check=True).stdout
    return json.loads(out.rsplit("@@", 1)[1])


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("threads") / "walk.bvh"
    write(synthetic_walk(n_frames=240, fps=30).motion, path)
    return path


def test_the_command_line_runs_blas_on_one_thread(walk_file):
    pytest.importorskip("typer")
    report = cli_pools(["info", walk_file])
    assert report["pools"], "numpy's BLAS should be loaded by info"
    assert {p["num_threads"] for p in report["pools"]} == {1}, report["pools"]
    if report["os_threads"] is not None:  # Linux: no BLAS worker thread was even started
        assert report["os_threads"] == 1


def test_mocycle_threads_allows_more(walk_file):
    pytest.importorskip("typer")
    report = cli_pools(["info", walk_file], MOCYCLE_THREADS="2")
    assert report["env"] == {"OMP_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}
    report = cli_pools(["info", walk_file], MOCYCLE_THREADS="0")  # the libraries' own default
    assert report["env"] == {"OMP_NUM_THREADS": None, "OPENBLAS_NUM_THREADS": None}


def test_a_variable_set_by_the_user_is_left_alone(walk_file):
    pytest.importorskip("typer")
    report = cli_pools(["info", walk_file], OPENBLAS_NUM_THREADS="2")
    assert report["env"] == {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "2"}


def test_the_command_line_turns_numpys_huge_page_advice_off_unless_told(walk_file):
    pytest.importorskip("typer")
    assert cli_pools(["info", walk_file])["hugepage"] is False
    assert cli_pools(["info", walk_file], NUMPY_MADVISE_HUGEPAGE="1")["hugepage"] is True


def test_a_bad_value_is_a_usage_error(walk_file):
    pytest.importorskip("typer")
    environ = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p), threads.ENV: "many"}
    out = subprocess.run([sys.executable, "-m", "mocycle", "info", str(walk_file)], capture_output=True, text=True,
                         env=environ)
    assert out.returncode == 2 and "MOCYCLE_THREADS" in out.stderr and "Traceback" not in out.stderr


def test_threads_reads_the_environment(monkeypatch):
    monkeypatch.delenv(threads.ENV, raising=False)
    assert threads.threads() == 1
    for text, expected in (("3", 3), (" 1 ", 1), ("0", None), ("auto", None)):
        monkeypatch.setenv(threads.ENV, text)
        assert threads.threads() == expected
    monkeypatch.setenv(threads.ENV, "-2")
    with pytest.raises(MocycleError, match="MOCYCLE_THREADS"):
        threads.threads()


def test_entry_points_limit_blas_and_restore_it(monkeypatch):
    monkeypatch.delenv(threads.ENV, raising=False)
    seen = []

    @threads.limit_threads
    def entry():
        seen.append({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})
        inner()

    @threads.limit_threads
    def inner():  # nested: already limited, nothing to do
        seen.append({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})

    with threadpool_limits(limits=2, user_api="blas"):
        before = {p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"}
        entry()
        after = {p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"}
    assert before == {2}  # the test can see a limit change
    assert seen == [{1}, {1}]
    assert after == before


def test_find_phase_runs_on_one_thread(monkeypatch):
    """A long library entry point, called from a script: BLAS is on one thread while it runs."""
    import mocycle.phase.analysis as analysis

    monkeypatch.delenv(threads.ENV, raising=False)
    seen = []
    real = analysis.phase_features

    def spy(*args, **kwargs):
        seen.append({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})
        return real(*args, **kwargs)

    monkeypatch.setattr(analysis, "phase_features", spy)
    with threadpool_limits(limits=2, user_api="blas"):
        assert {p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"} == {2}
        analysis.find_phase(synthetic_walk(n_frames=200).motion)
    assert seen and all(s == {1} for s in seen)


def test_this_suite_runs_blas_on_one_thread():
    """conftest pins the suite (and the commands it runs) to MOCYCLE_THREADS threads, one by default."""
    n = threads.threads()
    np.dot(np.ones((50, 50)), np.ones((50, 50)))  # BLAS loaded and used
    pools = threadpool_info()
    assert pools and all(p["num_threads"] <= (n or os.cpu_count()) for p in pools), pools
