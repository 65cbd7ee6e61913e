"""Shared fixtures: where the real captures live, and a skip when they are absent."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

try:
    from mocycle import threads
except ModuleNotFoundError:  # tests_blender loads this file for its helpers before the extension brings mocycle
    threads = None

# BLAS and OpenMP on one thread (MOCYCLE_THREADS) for the whole suite and the commands it runs: set before
# numpy loads when it has not yet, limited by threadpoolctl when a plugin loaded it first.
if threads is not None:
    threads.pin_environment()
    if "numpy" in sys.modules and threads.threads() is not None:  # pragma: no cover - depends on the plugins
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=threads.threads())
else:
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("MOCYCLE_SHARED_DATA", REPO.parent / "shared" / "data"))


def shared_path(*parts: str) -> Path:
    """Path to a file in ../shared/data; skips the calling test with a clear message if absent."""
    p = SHARED_DATA.joinpath(*parts)
    if not p.exists():
        pytest.skip(f"shared capture {p} is absent (clone ../shared beside the repo to run this test)")
    return p


def shared_files(folder: str, pattern: str = "*.bvh") -> list[Path]:
    """All files in a ../shared/data folder, or a skip when the folder is absent."""
    d = SHARED_DATA / folder
    if not d.is_dir():
        pytest.skip(f"shared data folder {d} is absent (clone ../shared beside the repo)")
    return sorted(d.glob(pattern))


@pytest.fixture
def shared_data() -> Path:
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data {SHARED_DATA} is absent (clone ../shared beside the repo)")
    return SHARED_DATA



# ``make check`` (pytest -m "not browser and not slow and not node") leaves these out; ``make test`` runs them:
# every command end to end against the recorded outputs, the batch runner's dask clusters, the fuzzers
# (hypothesis under memory and time limits), hostile command lines, the studio's server, fresh interpreters
# (start-up, threads, import orders) and the few tests over ten seconds each on a busy machine.
SLOW = ("tests/batch/", "tests/cli_json/", "_fuzz.py", "tests/test_cli_hostile.py",
        # start-up: `mocycle --help` importing no numpy and the command table are cheap (<0.5 s) and stay in the
        # fast tier; the runs of a whole loop and of a misspelt command in fresh interpreters (~3 s each) do not
        "tests/test_startup.py::test_loop_loads_only_what_a_loop_uses", "tests/test_startup.py::test_a_misspelt",
        "tests/test_threads.py", "tests/test_cli_polish.py", "tests/studio/test_studio_api.py",
        "::test_codec_modules_import_in_any_order", "::test_writing_holds_one_piece_of_text_at_a_time_not_the_take",
        "::test_a_long_query_is_measured_on_evenly_spread_windows_and_still_finds_itself")


def pytest_collection_modifyitems(items):
    for item in items:
        if any(part in item.nodeid or part in item.path.as_posix() for part in SLOW):
            item.add_marker(pytest.mark.slow)
        function = getattr(item, "function", None)
        if function is not None and "run_js(" in _source(function):  # the glTF tests' Node.js side
            item.add_marker(pytest.mark.node)


def _source(function) -> str:
    import inspect

    try:
        return inspect.getsource(function)
    except (OSError, TypeError):
        return ""
