"""The command line against absurd options, bad output paths and signals: one clear line, no traceback,
no partial or replaced file."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from helpers import random_motion
from mocycle.cli import app
from mocycle.datasets import synthetic_walk
from mocycle.io import write_bvh

runner = CliRunner()
SRC = str(Path(__file__).resolve().parents[1] / "src")


@pytest.fixture(scope="module")
def take(tmp_path_factory) -> Path:
    walk = synthetic_walk(n_frames=240, fps=60, seed=4).motion
    return write_bvh(walk, tmp_path_factory.mktemp("take") / "take.bvh")


def _fails(args, *phrases, code=1):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code == code, result.output
    assert not isinstance(result.exception, Exception) or isinstance(result.exception, SystemExit), result.exception
    for phrase in phrases:
        assert phrase in result.output, result.output
    return result


@pytest.mark.parametrize("args, phrase, code", [
    (["convert", "{take}", "{out}/c.bvh", "--fps", "9e5"], "MOCYCLE_MAX_FRAMES", 1),
    # the repeats are made per part: a part whose output would pass the limit does not loop (exit 3, its reason)
    (["loop", "{take}", "-o", "{out}/l.bvh", "--cycles", "100000"], "MOCYCLE_MAX_FRAMES", 3),
    (["stretch", "{take}", "--factor", "1e7", "-o", "{out}/s.bvh"], "MOCYCLE_MAX_FRAMES", 1),
    (["convert", "{take}", "{out}/c.bvh", "--fps", "1e-300"], "fps", 1),
    (["search", "{take}", "{out}", "--window", "inf"], "window", 2),   # a bad option value: a usage error
    (["demo", "--seed", "-1", "--out", "{out}/demo"], "seed", 1),
])
def test_absurd_options_are_one_line(take, tmp_path, args, phrase, code):
    args = [a.format(take=take, out=tmp_path) for a in args]
    result = _fails(args, phrase, code=code)
    assert "Traceback" not in result.output
    assert [p.name for p in tmp_path.iterdir() if p.suffix == ".bvh" or p.name.endswith(".tmp")] == []


def test_frame_limit_is_raised_by_the_environment(take, tmp_path, monkeypatch):
    monkeypatch.setenv("MOCYCLE_MAX_FRAMES", "2000")  # 240 frames at 60 fps -> 7967 frames at 2000 fps
    _fails(["convert", take, tmp_path / "c.bvh", "--fps", "2000"], "7,967 frames", "the limit is 2,000 frames")
    monkeypatch.setenv("MOCYCLE_MAX_FRAMES", "8000")
    assert runner.invoke(app, ["convert", str(take), str(tmp_path / "c.bvh"), "--fps", "2000"]).exit_code == 0


@pytest.mark.parametrize("command", [
    ["convert", "{take}", "{o}"], ["loop", "{take}", "-o", "{o}"], ["stretch", "{take}", "--factor", "2", "-o", "{o}"],
    ["swings", "{take}", "-o", "{o}"], ["swings", "{take}", "--playback", "{o}"], ["edit", "{take}", "--joint", "Spine",
                                                                                  "--swing", "0", "-o", "{o}"],
    ["compress", "{take}", "-o", "{o}"], ["phase", "{take}", "--plot", "{o}"],
])
def test_missing_output_folder_is_refused_before_the_work(take, tmp_path, command):
    suffix = {"compress": ".mck", "phase": ".png"}.get(command[0], ".bvh")
    if command[0] == "swings" and "-o" in command:
        suffix = ".mosw"
    target = tmp_path / "no" / "such" / f"out{suffix}"
    args = [a.format(take=take, o=target) for a in command]
    t0 = time.perf_counter()
    _fails(args, "does not exist")
    assert time.perf_counter() - t0 < 5  # refused before reading or computing
    assert not (tmp_path / "no").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_unwritable_output_folder_is_refused(take, tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    _fails(["swings", take, "-o", locked / "s.json"], "not writable")


def test_output_equal_to_an_input_needs_force(take, tmp_path):
    copy = tmp_path / "copy.bvh"
    copy.write_bytes(take.read_bytes())
    before = copy.read_bytes()
    for args in (["convert", copy, copy], ["loop", copy, "-o", copy], ["blend", copy, take, "-o", copy],
                 ["transition", take, copy, "-o", copy], ["stretch", copy, "--factor", "2", "-o", copy]):
        _fails(args, "--force")
        assert copy.read_bytes() == before
    result = runner.invoke(app, ["convert", str(copy), str(copy), "--range", "0:50", "--force"])
    assert result.exit_code == 0, result.output
    assert copy.read_bytes() != before


def test_json_never_holds_nan_or_infinity():
    import math

    from mocycle.cli.common import json_text

    text = json_text({"fps": math.inf, "metrics": {"seam": float("nan"), "ok": 1.5}, "list": [1.0, -math.inf]})
    facts = json.loads(text)  # strict JSON
    assert facts["fps"] is None and facts["metrics"]["seam"] is None and facts["list"] == [1.0, None]
    assert facts["null_because_not_finite"] == ["fps (inf)", "metrics.seam (nan)", "list[1] (-inf)"]
    assert "Infinity" not in text and "NaN" not in text


def test_denormal_frame_time_is_refused_with_its_line(tmp_path):
    text = write_bvh(random_motion(5), tmp_path / "m.bvh").read_text()
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("Frame Time"))
    lines[k] = "Frame Time: 5e-324"
    (tmp_path / "d.bvh").write_text("\n".join(lines) + "\n")
    _fails(["info", tmp_path / "d.bvh", "--json"], f"d.bvh:{k + 1}:", "frame time")


# -- signals ---------------------------------------------------------------

SLOW_WRITE = """
import sys, time
import mocycle.io.atomic as atomic
real = atomic.os.replace
def slow(src, dst):
    print("writing", flush=True)
    time.sleep(60)
    real(src, dst)
atomic.os.replace = slow
sys.argv = ["mocycle", "convert", sys.argv[1], sys.argv[2]]
from mocycle.cli import main
main()
"""


@pytest.mark.parametrize("sig, code, word", [(signal.SIGTERM, 143, "terminated"), (signal.SIGINT, 130, "interrupted")])
def test_signal_during_a_write_removes_the_temporary_file(take, tmp_path, sig, code, word):
    out = tmp_path / "out.bvh"
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.Popen([sys.executable, "-c", SLOW_WRITE, str(take), str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout.readline().strip() == "writing"
        assert any(p.name.endswith(".tmp") for p in tmp_path.iterdir())  # the write is under way
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == code, stderr
    assert stderr.strip() == word and "Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []  # no partial output, no temporary file


def test_signal_at_start_up_prints_no_traceback(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    script = "import os, signal\nfrom mocycle.cli import main\nos.kill(os.getpid(), signal.SIGINT)\nmain()"
    # the signal lands while main() imports the commands (typer, numpy, scipy)
    script = ("import os, signal, sys, threading\nfrom mocycle.cli import main\n"
              "sys.argv = ['mocycle', '--help']\n"
              "threading.Timer(0.01, lambda: os.kill(os.getpid(), signal.SIGINT)).start()\nmain()")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=60)
    assert "Traceback" not in proc.stderr
    assert proc.returncode in (0, 130)
