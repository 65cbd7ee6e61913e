"""``mocycle batch`` end to end on real dask clusters: a LocalCluster, and a ``dask scheduler`` with two
``dask worker`` processes on 127.0.0.1 (random free ports; all shut down after). Same results either way, and
a worker killed mid-run loses no take."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import mocycle
from mocycle.datasets import synthetic_nonperiodic, synthetic_run, synthetic_walk
from mocycle.datasets.asfamc_text import TINY_AMC, TINY_ASF

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
STARTUP_S = 60


@pytest.fixture(scope="module")
def library(tmp_path_factory) -> Path:
    """Seven small takes in two folders: five loops of different periods, no periodic motion, a broken file
    and a 3-frame ASF/AMC take (no periodic motion in it)."""
    root = tmp_path_factory.mktemp("library")
    (root / "walks").mkdir()
    (root / "other").mkdir()
    for k, period in enumerate((0.9, 1.0, 1.1)):
        mocycle.write(synthetic_walk(n_frames=120, fps=30, period_s=period, seed=k).motion,
                      root / "walks" / f"walk{k}.bvh")
    mocycle.write(synthetic_run(n_frames=120, fps=30).motion, root / "run.bvh")
    mocycle.write(synthetic_nonperiodic(n_frames=120, fps=30).motion, root / "other" / "noise.bvh")
    (root / "other" / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    (root / "other" / "01.asf").write_text(TINY_ASF)
    (root / "other" / "01_01.amc").write_text(TINY_AMC)
    return root


def batch(*args, timeout=240) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mocycle", "batch", *map(str, args)], capture_output=True,
                          text=True, env=ENV, timeout=timeout)


def rows_of(outdir: Path) -> dict[str, dict]:
    return {r["rel"]: r for r in json.loads((outdir / "results.json").read_text())["takes"]}


@pytest.fixture(scope="module")
def local_run(library, tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    r = batch("loop", library, "-o", out, "--workers", "2", "--harmonics", "8")
    assert r.returncode == 0, r.stderr
    return out, r


def _dask(*args) -> list[str]:
    script = Path(sys.executable).with_name("dask")
    return [str(script), *args] if script.exists() else [sys.executable, "-m", "dask", *args]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """``dask scheduler`` + two single-threaded ``dask worker`` processes (no nanny: killing one kills it)."""
    where = tmp_path_factory.mktemp("cluster")
    info = where / "scheduler.json"
    procs = [subprocess.Popen(_dask("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                    "--scheduler-file", info), env=ENV, cwd=where,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + STARTUP_S
        while not info.exists() or not info.read_text().strip():
            assert procs[0].poll() is None and time.monotonic() < deadline, "the dask scheduler did not start"
            time.sleep(0.1)
        address = json.loads(info.read_text())["address"]
        for k in range(2):
            procs.append(subprocess.Popen(
                _dask("worker", "--scheduler-file", info, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
                      "--no-dashboard", "--local-directory", where / f"w{k}", "--death-timeout", "60"),
                env=ENV, cwd=where, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address, procs[1:]
    finally:  # the workers first, then the scheduler
        for group in (procs[1:], procs[:1]):
            for p in group:
                if p.poll() is None:
                    p.send_signal(signal.SIGTERM)
            for p in group:
                try:
                    p.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
        assert all(p.returncode is not None for p in procs)


def _same(a: dict, b: dict) -> None:
    assert (a["status"], a["message"], a["file"]) == (b["status"], b["message"], b["file"])
    assert a["figures"].keys() == b["figures"].keys()
    for key, value in a["figures"].items():  # numbers within rounding; text (a part's kind, frames) the same
        if isinstance(value, int | float) and not isinstance(value, bool):
            assert b["figures"][key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
        else:
            assert b["figures"][key] == value, key


def test_a_local_batch_processes_every_take(library, local_run):
    out, r = local_run
    rows = rows_of(out)
    assert sorted(rows) == ["other/01_01.amc", "other/broken.bvh", "other/noise.bvh", "run.bvh", "walks/walk0.bvh",
                            "walks/walk1.bvh", "walks/walk2.bvh"]
    status = {rel: row["status"] for rel, row in rows.items()}
    assert status["other/noise.bvh"] == "no-periodic-motion" and status["other/broken.bvh"] == "error"
    assert status["other/01_01.amc"] == "no-periodic-motion"  # read through its .asf; 3 frames hold no cycle
    assert all(status[f"walks/walk{k}.bvh"] == "ok" for k in range(3)) and status["run.bvh"] == "ok"
    for k, period in enumerate((0.9, 1.0, 1.1)):  # the figures are the take's own: its period at 30 fps
        row = rows[f"walks/walk{k}.bvh"]
        assert row["figures"]["period_frames"] == pytest.approx(30 * period, rel=0.03)
        assert row["facts"]["harmonics"] == 8  # the command's options reached the task
        cycle = mocycle.read(out / "walks" / f"walk{k}.bvh")  # the output tree mirrors the input tree
        assert cycle.n_frames == row["figures"]["cycle_frames"]
    lines = r.stderr.splitlines()
    assert any(line.startswith("[7/7] ") for line in lines)  # plain progress lines off a terminal
    assert "7 takes: 4 ok, 2 no periodic motion, 0 refused, 1 error" in r.stdout
    head = (out / "results.csv").read_text().splitlines()[0]
    assert head.startswith("file,status,message,part,kind,frames,turn_per_cycle_deg,period_frames,periods,cycle_frames")
    assert len((out / "results.csv").read_text().splitlines()) == 8
    run = json.loads((out / "results.json").read_text())["run"]
    assert run["workers"] == 2  # forked from the warm forkserver where there is one (Linux has it)
    assert run["worker_start"] in (("forkserver",) if sys.platform == "linux" else ("forkserver", "spawn"))


def test_resume_starts_no_cluster_when_every_take_is_fresh(library, local_run, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(local_run[0], out)  # copy2: the times stay, so the copies are as fresh as the originals
    r = batch("loop", library / "walks", library / "run.bvh", "-o", out, "--harmonics", "8", "--resume", "--json")
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert (summary["takes"], summary["resumed"], summary["ok"], summary["engine"]) == (4, 4, 4, None)
    assert all(row["resumed"] for row in rows_of(out).values())


def test_a_scheduler_gives_the_same_results_as_a_local_run(library, local_run, cluster, tmp_path):
    address, workers = cluster
    from typer.testing import CliRunner

    from mocycle.cli import app

    r = CliRunner().invoke(app, ["batch", "loop", str(library), "-o", str(tmp_path), "--scheduler", address,
                                 "--workers", "2", "--harmonics", "8"])
    assert r.exit_code == 0, r.output
    local, remote = rows_of(local_run[0]), rows_of(tmp_path)
    assert sorted(local) == sorted(remote)
    for rel in local:
        _same(local[rel], remote[rel])
        for a, b in zip(local[rel]["outputs"], remote[rel]["outputs"], strict=True):
            assert a == b  # relative to the output folder
            x, y = mocycle.read(local_run[0] / a), mocycle.read(tmp_path / b)
            assert np.allclose(x.rotations, y.rotations, atol=1e-9)
    assert len({row["worker"] for row in remote.values()}) == 2  # both workers took takes
    from distributed import Client

    def pools():
        from threadpoolctl import threadpool_info

        return [(p["internal_api"], p["num_threads"]) for p in threadpool_info()]

    with Client(address, timeout=30) as client:  # no nanny set the variables: the batch's plugin pinned them
        threads = client.run(pools)
    assert len(threads) == 2 and all(apis for apis in threads.values()), threads
    assert all(n == 1 for apis in threads.values() for _, n in apis), threads


def _rescheduled(address: str) -> list[str]:
    """The takes the scheduler took back from a worker that left while running them."""
    from distributed import Client

    def lost(dask_scheduler):
        return sorted({str(t[0]) for t in dask_scheduler.transition_log
                       if str(t[0]).startswith("mocycle-") and t[1] == "processing" and t[2] == "released"})

    with Client(address, timeout=30) as client:
        return client.run_on_scheduler(lost)


def test_a_worker_killed_mid_run_loses_no_take(library, cluster, tmp_path):
    address, workers = cluster
    proc = subprocess.Popen([sys.executable, "-m", "mocycle", "batch", "loop", library / "walks", library / "run.bvh",
                             "-o", tmp_path, "--scheduler", address, "--workers", "2"],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not list(tmp_path.rglob("*.loop.json")):  # the first take is done: the others are in flight
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.02)
        workers[0].kill()
        workers[0].wait()
        stdout, stderr = proc.communicate(timeout=180)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, stderr
    rows = rows_of(tmp_path)
    assert sorted(rows) == ["run.bvh", "walks/walk0.bvh", "walks/walk1.bvh", "walks/walk2.bvh"]
    assert all(row["status"] == "ok" and (tmp_path / row["outputs"][0]).exists() for row in rows.values()), rows
    assert "4 takes: 4 ok" in stdout
    assert _rescheduled(address), "no take was running on the killed worker: nothing was tested"
