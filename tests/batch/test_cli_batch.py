"""``mocycle batch`` on the command line, without a cluster: parsing COMMAND's options, usage errors, the
progress display, and that neither ``mocycle --help`` nor ``import mocycle.batch`` loads dask."""

import io
import os
import subprocess
import sys

import pytest
from rich.console import Console
from typer.testing import CliRunner

import mocycle
from mocycle.batch.progress import BarProgress, LineProgress, progress_for
from mocycle.cli import app
from mocycle.cli.batch import parse_command_line
from mocycle.datasets import synthetic_walk


def test_the_options_of_command_are_its_task_options():
    command, inputs, options = parse_command_line(
        ["loop", "a.bvh", "--harmonics", "5", "dir", "--root", "motion", "--force", "--feet", "keep"])
    assert (command, inputs) == ("loop", ["a.bvh", "dir"])
    assert (options.harmonics, options.root, options.force, options.feet) == (5, "motion", True, "keep")
    assert options.method == "harmonic"  # the task's default for what was not given
    _, _, stretch = parse_command_line(["stretch", "x", "--factor", "2.5", "--window", "40", "--amc-fps", "60"])
    assert (stretch.factor, stretch.window_frames, stretch.amc_fps) == (2.5, 40, 60.0)


@pytest.fixture
def take(tmp_path):
    return mocycle.write(synthetic_walk(n_frames=90, fps=30).motion, tmp_path / "walk.bvh")


@pytest.mark.parametrize("args, code, message", [
    (["blend", "{take}"], 2, "COMMAND must be one of info, phase, loop, stretch, swings, compress; got 'blend'"),
    (["loop", "{take}", "--harmonic", "5"], 2, "No such option '--harmonic'"),
    (["loop", "{take}", "--harmonics", "0"], 2, "--harmonics must be 'auto' or a positive integer; got '0'"),
    (["stretch", "{take}"], 2, "Missing option '--factor'"),
    (["loop"], 1, "batch loop: no INPUTS"),
    (["loop", "{take}", "--suffix", ".mck"], 1, "--suffix: batch loop writes .bvh"),
    (["info", "{take}", "--suffix", ".bvh"], 1, "leave --suffix out"),
    (["loop", "{missing}"], 1, "no such file or folder"),
])
def test_usage_errors_say_what_is_wrong_before_any_work(tmp_path, take, args, code, message):
    args = [a.format(take=take, missing=tmp_path / "missing.bvh") for a in args]
    r = CliRunner().invoke(app, ["batch", *args, "-o", str(tmp_path / "out")])
    assert r.exit_code == code, r.output
    assert message in " ".join(r.stderr.split()) and "Traceback" not in r.output
    assert not (tmp_path / "out" / "results.csv").exists()


def test_an_output_that_would_replace_an_input_is_refused(take):
    r = CliRunner().invoke(app, ["batch", "loop", str(take), "-o", str(take.parent)])
    assert r.exit_code == 1 and "would replace an input" in r.stderr


def test_help_and_import_load_no_dask():
    code = ("import sys\nfrom typer.testing import CliRunner\nfrom mocycle.cli import app\nimport mocycle.batch\n"
            "r = CliRunner().invoke(app, ['--help'])\nassert 'batch' in r.output, r.output\n"
            "r = CliRunner().invoke(app, ['batch', '--help'])\nassert '--scheduler' in r.output, r.output\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


ROW = {"rel": "a/walk.bvh", "status": "ok", "message": "", "figures": {"period_frames": 30.04, "cycle_frames": 30}}


def test_progress_is_a_bar_on_a_terminal_and_lines_elsewhere():
    assert isinstance(progress_for(Console(file=io.StringIO(), force_terminal=True), 3), BarProgress)
    text = io.StringIO()
    shown = progress_for(Console(file=text, force_terminal=False, width=200), 3, resumed=1)
    assert isinstance(shown, LineProgress)
    with shown:
        shown.advance(ROW)
        shown.advance({**ROW, "status": "refused", "message": "the seam jumps"})
    lines = text.getvalue().splitlines()
    assert lines[0] == "1 take(s) kept from the earlier run (--resume)"
    assert lines[1].startswith("[2/3] a/walk.bvh: ok (period_frames 30.04, cycle_frames 30); not ok 0, ")
    assert lines[2].startswith("[3/3] a/walk.bvh: refused: the seam jumps; not ok 1, ")


def test_the_bar_counts_done_and_not_ok():
    text = io.StringIO()
    with BarProgress(Console(file=text, force_terminal=True, width=120), 4, resumed=1) as bar:
        bar.advance(ROW)
        bar.advance({**ROW, "status": "error", "message": "bad"})
    task = bar.progress.tasks[0]
    assert (task.completed, task.total, task.fields["failed"]) == (3, 4, 1)
    assert "3/4" in text.getvalue() and "not ok 1" in text.getvalue()


def test_no_scheduler_is_a_failed_run(take, tmp_path):
    import socket

    import dask
    import distributed  # noqa: F401  (its defaults first: a dask.config.set of a key dask does not know yet
    # would remove the whole "distributed" section on exit, and the later tests' clients would find no config)

    with socket.socket() as s:  # a free port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        r = CliRunner().invoke(app, ["batch", "info", str(take), "-o", str(tmp_path / "out"), "--scheduler",
                                     f"tcp://127.0.0.1:{port}"])
    assert r.exit_code == 1, r.output
    assert f"the batch stopped (on the dask scheduler at tcp://127.0.0.1:{port})" in r.stderr
    assert not (tmp_path / "out" / "results.csv").exists()
