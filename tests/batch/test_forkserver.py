"""Warm workers: each command's preload list holds what its task imports, the forkserver starts with it and
stops after the batch, and the takes go largest first."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import mocycle
from mocycle.batch.commands import COMMANDS
from mocycle.batch.discover import Take
from mocycle.datasets import synthetic_walk

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}

#: a required option of some commands
OPTIONS = {"stretch": {"factor": 1.5}}

#: in a fresh interpreter: import what a warm worker has, run one take, print the modules it imported then
#: (besides the standard library's)
NEW_MODULES = """
import importlib, json, sys
from pathlib import Path
from mocycle.batch.commands import COMMANDS
from mocycle.batch.forkserver import WORKER_MODULES
command, source, outdir, options = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3]), json.loads(sys.argv[4])
for name in (*WORKER_MODULES, *COMMANDS[command].imports):
    importlib.import_module(name)
from mocycle import tasks
from mocycle.batch.discover import Take
from mocycle.batch.take import Job, process
job = Job(command, getattr(tasks, command).Options(**options), outdir, COMMANDS[command].suffix)
before = set(sys.modules)
row = process(job, Take(source, Path(source.name)))
new = sorted(m for m in set(sys.modules) - before if m.split(".")[0] not in sys.stdlib_module_names)
print(json.dumps({"status": row["status"], "message": row["message"], "new": new}))
"""


@pytest.fixture(scope="module")
def walk(tmp_path_factory) -> Path:
    return mocycle.write(synthetic_walk(n_frames=150, fps=30).motion, tmp_path_factory.mktemp("in") / "walk.bvh")


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_warm_worker_imports_nothing_more_for_its_first_take(command, walk, tmp_path):
    r = subprocess.run([sys.executable, "-c", NEW_MODULES, command, str(walk), str(tmp_path),
                        json.dumps(OPTIONS.get(command, {}))], capture_output=True, text=True, env=ENV, timeout=120)
    assert r.returncode == 0, r.stderr
    seen = json.loads(r.stdout.strip().splitlines()[-1])
    assert seen["status"] == "ok", seen["message"]
    assert seen["new"] == [], f"add to COMMANDS[{command!r}].imports: {seen['new']}"


def test_the_forkserver_preloads_and_stops_after_the_block(tmp_path):
    script = """
import os
from multiprocessing import get_context
from mocycle.batch import forkserver

def probe(q):
    import sys
    q.put(("mocycle.cycle" in sys.modules, os.environ.get("OPENBLAS_NUM_THREADS")))

if __name__ == "__main__":
    assert not forkserver.running()
    with forkserver.warm_workers(["mocycle.cycle"]) as warm:
        assert warm and forkserver.running()
        with forkserver.warm_workers(["mocycle.phase"]) as again:  # the running one is kept, and not stopped
            assert again
        assert forkserver.running()
        ctx = get_context(forkserver.METHOD)
        q = ctx.Queue()
        p = ctx.Process(target=probe, args=(q,))
        p.start()
        print(q.get(timeout=60))
        p.join()
    assert not forkserver.running()
"""
    (tmp_path / "probe.py").write_text(script)
    r = subprocess.run([sys.executable, str(tmp_path / "probe.py")], capture_output=True, text=True, timeout=120,
                       env={**ENV, "OPENBLAS_NUM_THREADS": "4"})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "(True, '1')"  # preloaded, and one BLAS thread whatever this process had


def test_the_largest_takes_go_first(tmp_path):
    pytest.importorskip("distributed")
    from mocycle.batch.engine import largest_first

    takes = []
    for name, size in (("a.bvh", 10), ("b.bvh", 300), ("c.bvh", 20), ("gone.bvh", None)):
        path = tmp_path / name
        if size is not None:
            path.write_bytes(b"x" * size)
        takes.append(Take(source=path, rel=Path(name)))
    assert [t.rel.name for t in largest_first(takes)] == ["b.bvh", "c.bvh", "a.bvh", "gone.bvh"]
