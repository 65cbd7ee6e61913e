"""``mocycle batch`` against a folder of odd names (issue 30): outputs whose names collide are refused before any
work, ``--resume`` keeps only what it can verify, every path found gets a row (broken links, link loops,
unreadable folders and files, pipes), the output folder is checked first, and names that are not UTF-8 or hold
control characters reach the rows, the CSV and the terminal as printable text."""

from __future__ import annotations

import errno
import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from rich.console import Console
from typer.testing import CliRunner

import mocycle
from mocycle import tasks
from mocycle.batch import check_collisions, run_batch
from mocycle.batch.commands import COMMANDS
from mocycle.batch.discover import Take, find_takes
from mocycle.batch.progress import LineProgress
from mocycle.batch.take import Job, fresh_record, process
from mocycle.cli import app
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
BAD = b"bad\xffname.bvh"  # a file name that is not UTF-8


@pytest.fixture(scope="module")
def walk_text(tmp_path_factory) -> str:
    return mocycle.write(synthetic_walk(n_frames=90, fps=30).motion,
                         tmp_path_factory.mktemp("walk") / "walk.bvh").read_text()


def _takes(folder: Path, text: str, *names: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_text(text)
    return folder


def _job(outdir: Path, command="swings", suffix=".json", **options) -> Job:
    return Job(command=command, options=tasks.TASKS[command].Options(**options), outdir=outdir, suffix=suffix)


def _cli(*args):
    return CliRunner().invoke(app, ["batch", *map(str, args)])


# ------------------------------------------------------------------------------------------ output collisions
def test_the_issues_colliding_names_are_refused_before_any_work(tmp_path, walk_text):
    """walk.bvh's record walk.swings.json is walk.swings.bvh's output; results.bvh's output is results.json."""
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh", "walk.swings.bvh", "results.bvh")
    r = _cli("swings", folder, "-o", tmp_path / "out", "--suffix", ".json")
    assert r.exit_code == 1, r.output
    message = " ".join(r.stderr.split())
    assert message.startswith("error: output names collide, nothing was run:")
    assert "results.json would be the batch's results.json and the output of results.bvh" in message
    assert "walk.swings.json would be the record of walk.bvh and the output of walk.swings.bvh" in message
    assert "Traceback" not in r.output and len(r.stderr.strip().splitlines()) <= 3
    assert not (tmp_path / "out").exists()  # nothing was made, nothing overwritten


def test_the_same_takes_with_their_default_suffix_do_not_collide(tmp_path, walk_text):
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh", "walk.swings.bvh", "results.bvh")
    out = tmp_path / "out"
    check_collisions(_job(out, suffix=".mosw"), find_takes([folder], out))  # no error
    with pytest.raises(MocycleError, match="collide"):
        check_collisions(_job(out, suffix=".json"), find_takes([folder], out))


def test_every_class_output_of_which_all_is_claimed(tmp_path, walk_text):
    """``loop --part all`` writes walk.part<K>-<kind>.bvh: a take named walk.part1-arms.bvh would be
    overwritten."""
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh", "walk.part1-arms.bvh")
    out = tmp_path / "out"
    job = Job(command="loop", options=tasks.loop.Options(which="all"), outdir=out, suffix=".bvh")
    with pytest.raises(MocycleError, match=r"walk\.part1-arms\.bvh would be the outputs of walk\.bvh \(--part all\)"):
        check_collisions(job, find_takes([folder], out))
    check_collisions(Job(command="loop", options=tasks.loop.Options(), outdir=out, suffix=".bvh"),
                     find_takes([folder], out))  # one class each: no collision


# ------------------------------------------------------------------------------------------ --resume verifies
def _ran(tmp_path, walk_text, names=("walk.bvh",)):
    folder = _takes(tmp_path / "in", walk_text, *names)
    job = _job(tmp_path / "out", suffix=".json")
    takes = find_takes([folder], job.outdir)
    for take in takes:
        assert process(job, take)["status"] == "ok"
    return job, takes


def test_resume_keeps_a_verified_record(tmp_path, walk_text):
    job, (take,) = _ran(tmp_path, walk_text)
    row = fresh_record(job, take)
    assert row is not None and row["outputs"] == ["walk.json"]
    (check,) = row["output_checks"]
    assert check["tail"] == ".json" and check["bytes"] == (job.outdir / "walk.json").stat().st_size
    assert len(check["sha256"]) == 64


@pytest.mark.parametrize("tamper", ["output replaced", "output same size", "output gone", "record of another take",
                                    "record without checks"])
def test_resume_runs_again_what_it_cannot_verify(tmp_path, walk_text, tamper):
    job, takes = _ran(tmp_path, walk_text, ("walk.bvh", "other.bvh"))
    take = next(t for t in takes if t.rel.name == "walk.bvh")
    output, record = job.outdir / "walk.json", job.record_path(take)
    if tamper == "output replaced":  # the issue: a take's output holding another file
        output.write_text(json.dumps({"not": "the take's segmentation"}))
    elif tamper == "output same size":
        data = bytearray(output.read_bytes())
        data[len(data) // 2] ^= 1
        output.write_bytes(bytes(data))
    elif tamper == "output gone":
        output.unlink()
    elif tamper == "record of another take":  # a record moved or copied to this take's place
        shutil.copy2(job.record_path(next(t for t in takes if t is not take)), record)
    else:  # a record as mocycle wrote it before it kept the outputs' sizes and hashes
        row = json.loads(record.read_text())
        del row["output_checks"]
        record.write_text(json.dumps(row))
    assert fresh_record(job, take) is None
    rerun = process(job, take)  # running it again mends the tree
    assert rerun["status"] == "ok" and fresh_record(job, take) is not None


# ------------------------------------------------------------------------------------------ a row for every path
def test_every_path_found_gets_a_take_or_a_problem(tmp_path, walk_text, monkeypatch):
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh")
    (folder / "dangling.bvh").symlink_to(folder / "nowhere.bvh")
    (folder / "loop.bvh").symlink_to(folder / "loop.bvh")
    (folder / "sub").mkdir()
    (folder / "sub" / "up").symlink_to(folder)  # a folder link back to an ancestor
    os.mkfifo(folder / "pipe.bvh")  # reading it would block a worker for ever
    (folder / "locked").mkdir()
    _takes(folder / "locked", walk_text, "hidden.bvh")
    (folder / "secret.bvh").write_text(walk_text)
    real_scandir, real_access = os.scandir, os.access

    def scandir(path):  # root reads every folder: the permission error is made here
        if Path(path).name == "locked":
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_scandir(path)

    monkeypatch.setattr(os, "scandir", scandir)
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: Path(p).name != "secret.bvh" and real_access(p, mode))
    found = {t.rel.as_posix(): t.problem for t in find_takes([folder])}
    assert found == {
        "walk.bvh": None,
        "dangling.bvh": f"a broken symbolic link (to {folder / 'nowhere.bvh'})",
        "loop.bvh": "a symbolic link loop",
        "sub/up": "a symbolic link loop (it leads back to a folder above it)",
        "pipe.bvh": "not a regular file (a device, pipe or socket)",
        "locked": "cannot read the folder (Permission denied)",
        "secret.bvh": "cannot read the file (Permission denied)",
    }


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads every folder and file")
def test_real_permissions_give_rows(tmp_path, walk_text):
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh", "secret.bvh")
    (folder / "locked").mkdir()
    (folder / "secret.bvh").chmod(0)
    (folder / "locked").chmod(0)
    try:
        found = {t.rel.as_posix(): t.problem for t in find_takes([folder])}
    finally:
        (folder / "locked").chmod(0o755)
    assert found["secret.bvh"].startswith("cannot read the file") and found["locked"].startswith("cannot read")


def test_a_folder_of_unreadable_paths_gives_error_rows_without_a_cluster(tmp_path):
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "dangling.bvh").symlink_to(folder / "nowhere.bvh")
    (folder / "loop.amc").symlink_to(folder / "loop.amc")
    rows, run = run_batch("info", [folder], tmp_path / "out", tasks.info.Options())
    assert [(r["rel"], r["status"]) for r in rows] == [("dangling.bvh", "error"), ("loop.amc", "error")]
    assert rows[1]["message"] == "a symbolic link loop" and run["engine"] is None and run["error"] == 2
    csv = (tmp_path / "out" / "results.csv").read_text().splitlines()
    assert len(csv) == 3 and csv[1].endswith(",error,a broken symbolic link (to " + str(folder / "nowhere.bvh")
                                             + "),,,,,,,,,")


def test_a_broken_link_named_as_input_is_one_error(tmp_path):
    (tmp_path / "dangling.bvh").symlink_to(tmp_path / "nowhere.bvh")
    r = _cli("info", tmp_path / "dangling.bvh", "-o", tmp_path / "out")
    assert r.exit_code == 1 and "dangling.bvh: a broken symbolic link" in r.stderr and "Traceback" not in r.output


# ------------------------------------------------------------------------------------------ -o checked first
@pytest.mark.parametrize("case, phrase", [
    ("a file", "-o names a file; it must be a folder"),
    ("below a file", "is a file, not a folder"),
    ("not writable", "is not writable"),
    ("read-only file system", "cannot write in this folder (Read-only file system)"),
    ("the take itself", "-o names a file; it must be a folder"),
])
def test_a_bad_output_folder_is_one_line_before_any_work(tmp_path, walk_text, monkeypatch, case, phrase):
    import tempfile

    folder = _takes(tmp_path / "in", walk_text, "walk.bvh")
    (tmp_path / "file").write_text("x")
    out = {"a file": tmp_path / "file", "below a file": tmp_path / "file" / "out",
           "the take itself": folder / "walk.bvh"}.get(case, tmp_path / "ro" / "out")
    if case == "not writable":
        (tmp_path / "ro").mkdir()
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, mode, **kw: Path(p) != tmp_path / "ro" and real(p, mode))
    if case == "read-only file system":
        def refuse(*args, **kwargs):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))

        monkeypatch.setattr(tempfile, "TemporaryFile", refuse)
    r = _cli("info", folder, "-o", out)
    assert r.exit_code == 1, r.output
    assert phrase in " ".join(r.stderr.split()) and len(r.stderr.strip().splitlines()) <= 2
    assert "Traceback" not in r.output and "no .bvh or .amc" not in r.output and "stopped" not in r.output
    assert not list((tmp_path / "file").parent.rglob("results.csv"))
    assert (folder / "walk.bvh").read_text() == walk_text


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_a_read_only_output_folder_is_refused(tmp_path, walk_text):
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        r = _cli("info", folder, "-o", ro / "out")
    finally:
        ro.chmod(0o755)
    assert r.exit_code == 1 and "not writable" in r.stderr and "Traceback" not in r.output


# ------------------------------------------------------------------------------------------ names that are not text
def test_a_take_name_that_is_not_utf8_runs_and_resumes(tmp_path, walk_text):
    """The issue: UnicodeEncodeError in results.py, on every --resume too. Now the row names it printably, with
    its bytes in file_hex; its record lies beside it under its real name; --resume keeps it."""
    folder = tmp_path / "in"
    folder.mkdir()
    with open(os.path.join(os.fsencode(folder), BAD), "w") as fh:
        fh.write(walk_text)
    with open(os.path.join(os.fsencode(folder), b"[link=x]y\x1b[31m.bvh"), "w") as fh:
        fh.write(walk_text)
    (folder / "dangling\x07.bvh").symlink_to(folder / "nowhere.bvh")
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "mocycle", "batch", "info", os.fsencode(folder), "-o", out,
                          "--workers", "1"], capture_output=True, env=ENV, timeout=300)
    assert run.returncode == 0, run.stderr
    text = (run.stdout + run.stderr).decode("utf-8")  # strict: the terminal got UTF-8
    assert "\x1b" not in text and "\x07" not in text and "Traceback" not in text
    assert "bad\\xffname.bvh: ok" in text and "[link=x]y\\x1b[31m.bvh: ok" in text
    assert "3 takes: 2 ok, 0 no periodic motion, 0 refused, 1 error" in text
    rows = {r["rel"]: r for r in json.loads((out / "results.json").read_bytes().decode("utf-8"))["takes"]}
    assert set(rows) == {"bad\\xffname.bvh", "[link=x]y\\x1b[31m.bvh", "dangling\\x07.bvh"}
    bad = rows["bad\\xffname.bvh"]
    assert bad["status"] == "ok" and bytes.fromhex(bad["file_hex"]) == os.path.join(os.fsencode(folder), BAD)
    assert bad["file"] == str(folder / "bad\\xffname.bvh") and bad["facts"]["frames"] == 90
    assert "file_hex" not in rows["[link=x]y\\x1b[31m.bvh"]  # its name is text: no bytes needed
    assert os.path.exists(os.path.join(os.fsencode(out), b"bad\xffname.info.json"))  # the real name
    csv = (out / "results.csv").read_bytes().decode("utf-8")
    assert "bad\\xffname.bvh,ok," in csv and "\x1b" not in csv and "\x07" not in csv
    again = subprocess.run([sys.executable, "-m", "mocycle", "batch", "info", os.fsencode(folder), "-o", out,
                            "--resume", "--json"], capture_output=True, env=ENV, timeout=300)
    assert again.returncode == 0, again.stderr
    summary = json.loads(again.stdout)
    assert (summary["resumed"], summary["ok"], summary["error"], summary["engine"]) == (2, 2, 1, None)


def test_progress_lines_show_names_as_text():
    buffer = io.StringIO()
    console = Console(file=buffer, width=200, force_terminal=False)
    progress = LineProgress(console, 1)
    progress.advance({"rel": "[link=x]y\x1b[31m\udcff.bvh", "status": "error", "message": "bad \x1b]8;;x\x07",
                      "figures": {}})
    line = buffer.getvalue()
    assert "\x1b" not in line and "\x07" not in line
    assert "[link=x]y\\x1b[31m\\xff.bvh: error: bad \\x1b]8;;x\\x07" in line


def test_a_record_names_its_outputs_by_tail_so_any_take_name_resumes(tmp_path, walk_text):
    folder = tmp_path / "in"
    folder.mkdir()
    with open(os.path.join(os.fsencode(folder), BAD), "w") as fh:
        fh.write(walk_text)
    (take,) = find_takes([os.fsdecode(os.path.join(os.fsencode(folder), BAD))])
    job = _job(tmp_path / "out", suffix=".mosw")
    row = process(job, take)
    assert row["status"] == "ok" and row["outputs"] == ["bad\\xffname.mosw"]
    assert [c["tail"] for c in row["output_checks"]] == [".mosw"]
    assert fresh_record(job, take) is not None
    assert isinstance(take, Take) and COMMANDS["swings"].suffix == ".mosw"


def test_an_input_folder_inside_the_output_folder_is_searched_whole(tmp_path, walk_text):
    """``-o .`` from the folder that holds the input folder: the takes are found (before: "no .bvh or .amc files
    in this folder", as everything under the output folder was left out)."""
    folder = _takes(tmp_path / "in", walk_text, "walk.bvh")
    assert [t.rel.as_posix() for t in find_takes([folder], tmp_path)] == ["walk.bvh"]
    (folder / "out").mkdir()
    (folder / "out" / "old.bvh").write_text("an earlier output")  # outputs inside the input tree: left out
    assert [t.rel.as_posix() for t in find_takes([folder], folder / "out")] == ["walk.bvh"]
