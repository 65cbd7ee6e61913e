"""A take is a row (issue 36): whatever one take does (a name too long for a temporary file, a glTF whose buffer is
a FIFO, a deflate bomb, a record that cannot be written, a take running past the time limit), the batch gives it
an ``error`` row, goes on and writes ``results.*``; ``--json`` prints JSON also when the batch is refused."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import mocycle
from mocycle import tasks
from mocycle.batch.discover import Take
from mocycle.batch.take import Job, process
from mocycle.datasets import synthetic_walk
from mocycle.datasets.fbx_files import bomb_scene, write_fbx
from mocycle.datasets.gltf_files import chain_document, gltf_file

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}


def batch(*args, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mocycle", "batch", *map(str, args)], capture_output=True,
                          text=True, env=ENV, timeout=timeout)


def rows_of(outdir: Path) -> dict[str, dict]:
    return {r["rel"]: r for r in json.loads((outdir / "results.json").read_text())["takes"]}


@pytest.fixture(scope="module")
def hostile_folder(tmp_path_factory) -> Path:
    """A good take, one named with 235 letters, a glTF whose buffer is a FIFO beside it, an FBX deflate bomb."""
    root = tmp_path_factory.mktemp("hostile")
    walk = synthetic_walk(n_frames=120, fps=30).motion
    mocycle.write(walk, root / "good.bvh")
    mocycle.write(walk, root / ("w" * 235 + ".bvh"))
    doc, blob = chain_document(3)
    gltf_file(root / "piped.gltf", doc, blob, uri="piped.bin")
    (root / "piped.bin").unlink()
    os.mkfifo(root / "piped.bin")
    write_fbx(root / "bomb.fbx", bomb_scene())
    return root


def test_a_batch_over_hostile_takes_ends_with_a_row_per_take(hostile_folder, tmp_path):
    out = tmp_path / "out"
    t0 = time.monotonic()
    r = batch("loop", hostile_folder, "-o", out, "--workers", "2")
    assert r.returncode == 0, r.stderr
    assert time.monotonic() - t0 < 240
    assert "Traceback" not in r.stderr and "Compute Failed" not in r.stderr
    rows = rows_of(out)
    long = "w" * 235 + ".bvh"
    assert sorted(rows) == sorted(["good.bvh", long, "piped.gltf", "bomb.fbx"])
    assert rows["good.bvh"]["status"] == "ok" and rows[long]["status"] == "ok", rows[long]["message"]
    assert (out / ("w" * 235 + ".loop.json")).is_file() and (out / long).is_file()
    assert rows["piped.gltf"]["status"] == "error" and "a named pipe, not a regular file" in rows["piped.gltf"][
        "message"]
    assert rows["bomb.fbx"]["status"] == "error" and "deflate bomb" in rows["bomb.fbx"]["message"]
    assert (out / "results.csv").is_file()
    assert not [p for p in out.rglob("*.tmp")]
    again = batch("loop", hostile_folder, "-o", out, "--workers", "2", "--resume")  # the folder can finish
    assert again.returncode == 0 and "2 kept (--resume)" in again.stdout, again.stdout + again.stderr


def job_for(tmp_path, command="info", **options) -> Job:
    return Job(command=command, options=tasks.TASKS[command].Options(**options), outdir=tmp_path / "out",
               suffix=None)


def test_a_record_that_cannot_be_written_is_the_rows_error(tmp_path):
    take_file = mocycle.write(synthetic_walk(n_frames=60, fps=30).motion, tmp_path / "walk.bvh")
    job = job_for(tmp_path)
    take = Take(source=take_file, rel=Path("walk.bvh"))
    job.record_path(take).mkdir(parents=True)  # a folder where the record goes: nothing can replace it
    row = process(job, take)
    assert row["status"] == "error" and "cannot write its record walk.info.json" in row["message"]
    assert row["record"] is None
    long_file = mocycle.write(synthetic_walk(n_frames=60, fps=30).motion, tmp_path / ("x" * 248 + ".bvh"))
    row = process(job, Take(source=long_file, rel=Path(long_file.name)))  # its record's name passes 255 bytes
    assert row["status"] == "error" and "File name too long" in row["message"]


def test_a_take_past_the_time_limit_is_an_error_row_and_the_batch_goes_on(tmp_path):
    """A 0.5 s limit on loops of 30,000 frames: each runs over it (6,000 frames took under 0.5 s on a fast
    machine); its worker is stopped and replaced, its row says so, and the short take beside them is done."""
    (tmp_path / "in").mkdir()
    for k in range(2):
        mocycle.write(synthetic_walk(n_frames=30_000, fps=60, seed=k).motion, tmp_path / "in" / f"long{k}.bvh")
    mocycle.write(synthetic_walk(n_frames=40, fps=30).motion, tmp_path / "in" / "short.bvh")
    out = tmp_path / "out"
    r = batch("loop", tmp_path / "in", "-o", out, "--workers", "2", "--take-timeout", "0.5")
    assert r.returncode == 0, r.stderr
    rows = rows_of(out)
    assert rows["short.bvh"]["status"] == "ok"
    for k in range(2):
        row = rows[f"long{k}.bvh"]
        assert row["status"] == "error" and "ran longer than --take-timeout (0.5 s)" in row["message"], row


def test_batch_json_on_a_refused_run(tmp_path):
    mocycle.write(synthetic_walk(n_frames=60, fps=30).motion, tmp_path / "walk.bvh")
    r = batch("loop", tmp_path / "walk.bvh", "-o", tmp_path / "walk.bvh", "--json")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    said = json.loads(r.stdout)
    assert said["status"] == "error" and "-o names a file" in said["error"]
