"""One take as a worker runs it, without dask: statuses, outputs, records and what --resume keeps."""

import json
import os
from pathlib import Path

import pytest

import mocycle
from mocycle import tasks
from mocycle.batch.commands import COMMANDS, check_suffix
from mocycle.batch.discover import Take
from mocycle.batch.take import Job, fresh_record, process, status_of
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk
from mocycle.errors import DataError, Hint, LoopRefused, MocycleError, MotionFileError, NoPeriodicMotion, OptionError


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("in")
    return mocycle.write(synthetic_walk(n_frames=150, fps=30).motion, folder / "walk.bvh")


@pytest.fixture(scope="module")
def short_walk(tmp_path_factory):
    folder = tmp_path_factory.mktemp("short")
    return mocycle.write(synthetic_walk(n_frames=90, fps=30).motion, folder / "walk.bvh")


def _take(path: Path) -> Take:
    return Take(source=path.resolve(), rel=Path(path.name))


def _job(tmp_path, command="loop", **options):
    return Job(command=command, options=tasks.TASKS[command].Options(**options), outdir=tmp_path / "out",
               suffix=COMMANDS[command].suffix)


@pytest.mark.parametrize("exc, status", [
    (NoPeriodicMotion("none"), "no-periodic-motion"), (LoopRefused("seam"), "refused"),
    (MotionFileError("bad", "x.bvh", 3), "error"), (DataError("nan"), "error"), (OptionError("joints", "x"), "error"),
    (MocycleError("other"), "error"), (ZeroDivisionError("bug"), "error")])
def test_status_of_each_exception(exc, status):
    assert status_of(exc) == status


def test_an_ok_take_writes_its_output_and_record(tmp_path, walk_file):
    job = _job(tmp_path)
    row = process(job, _take(walk_file))
    assert row["status"] == "ok" and row["message"] == ""
    assert row["outputs"] == ["walk.bvh"]  # relative to the output folder
    cycle = mocycle.read(tmp_path / "out" / "walk.bvh")
    assert cycle.n_frames == row["figures"]["cycle_frames"] == row["facts"]["cycle_frames"]
    assert 29 < row["figures"]["period_frames"] < 31  # the walk's period is 1 s at 30 fps
    record = json.loads((tmp_path / "out" / "walk.loop.json").read_text())
    assert record["status"] == "ok" and record["options_hash"] == job.options_hash
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.endswith(".tmp")]


def test_refused_and_no_periodic_motion_and_bugs_are_rows_not_exceptions(tmp_path, walk_file, monkeypatch):
    job = _job(tmp_path)
    process(job, _take(walk_file))  # an ok run first: its loop must go when the take is refused later
    assert (tmp_path / "out" / "walk.bvh").exists()

    def refuse(path, options):
        raise LoopRefused(f"the seam jumps 4.2x the median step; {Hint('force')} writes it anyway", failed=["seam"])

    monkeypatch.setattr(tasks.loop, "run", refuse)
    row = process(job, _take(walk_file))
    # batch runs from a shell: the library's hint is said as the loop command's flag
    assert (row["status"], row["message"], row["outputs"]) == \
        ("refused", "the seam jumps 4.2x the median step; --force writes it anyway", [])
    assert not (tmp_path / "out" / "walk.bvh").exists()  # the tree agrees with the row

    monkeypatch.setattr(tasks.loop, "run", lambda path, options: 1 / 0)
    row = process(job, _take(walk_file))
    assert row["status"] == "error" and row["message"].startswith("ZeroDivisionError: division by zero (at ")


def test_a_take_without_periodic_motion(tmp_path):
    path = mocycle.write(synthetic_nonperiodic(n_frames=150, fps=30).motion, tmp_path / "noise.bvh")
    for command, words in (("loop", "no repeating motion"), ("phase", "no repeating motion")):
        row = process(_job(tmp_path, command), _take(path))
        assert row["status"] == "no-periodic-motion" and words in row["message"], command
        assert row["outputs"] == []


def test_a_bad_file_is_an_error_naming_the_line(tmp_path):
    path = tmp_path / "bad.bvh"
    path.write_text("HIERARCHY\nROOT Hips\n")
    row = process(_job(tmp_path, "info"), _take(path))
    assert row["status"] == "error" and f"{path.resolve()}:3:" in row["message"]
    assert (tmp_path / "out" / "bad.info.json").exists()


def test_resume_keeps_a_fresh_record_only(tmp_path, walk_file):
    source = tmp_path / "walk.bvh"
    source.write_bytes(walk_file.read_bytes())
    take, job = _take(source), _job(tmp_path, harmonics=5)
    assert fresh_record(job, take) is None  # nothing yet
    process(job, take)
    assert fresh_record(job, take)["status"] == "ok"
    assert fresh_record(_job(tmp_path, harmonics=6), take) is None  # other options
    assert fresh_record(Job("loop", job.options, job.outdir, ".bvh"), take) is not None
    earlier = source.stat().st_mtime - 10
    os.utime(tmp_path / "out" / "walk.bvh", (earlier, earlier))  # the input changed after the output was made
    assert fresh_record(job, take) is None
    process(job, take)
    assert fresh_record(job, take) is not None
    (tmp_path / "out" / "walk.bvh").unlink()  # an output is missing
    assert fresh_record(job, take) is None


def test_resume_runs_errors_again(tmp_path):
    path = tmp_path / "bad.bvh"
    path.write_text("HIERARCHY\n")
    job = _job(tmp_path, "info")
    process(job, _take(path))
    assert fresh_record(job, _take(path)) is None


def test_output_suffixes_per_command():
    assert check_suffix(COMMANDS["loop"], None) == ".bvh" and check_suffix(COMMANDS["loop"], "BVH") == ".bvh"
    assert check_suffix(COMMANDS["swings"], ".json") == ".json" and check_suffix(COMMANDS["compress"], None) == ".mck"
    assert check_suffix(COMMANDS["info"], None) is None
    with pytest.raises(MocycleError, match="batch loop writes .bvh"):
        check_suffix(COMMANDS["loop"], ".mck")
    with pytest.raises(MocycleError, match="leave --suffix out"):
        check_suffix(COMMANDS["phase"], ".json")


@pytest.mark.parametrize("command, options, suffix, outputs", [
    ("info", {}, None, []), ("phase", {}, None, []),
    ("loop", {"which": "all"}, ".bvh", ["walk.part0-periodic.bvh"]),
    ("swings", {}, ".json", ["walk.json"]), ("compress", {}, ".mck", ["walk.mck"]),
    ("stretch", {"factor": 1.5}, ".bvh", ["walk.bvh"])])
def test_every_command_writes_its_output_and_figures(tmp_path, short_walk, command, options, suffix, outputs):
    job = Job(command=command, options=tasks.TASKS[command].Options(**options), outdir=tmp_path, suffix=suffix)
    row = process(job, _take(short_walk))
    assert row["status"] == "ok", row["message"]
    assert row["outputs"] == outputs and all((tmp_path / p).exists() for p in outputs)
    assert set(row["figures"]) == set(COMMANDS[command].figures)
    # every figure made (a take looped whole, not cut into parts, has no part index)
    assert all(v is not None for k, v in row["figures"].items() if k != "part"), row["figures"]
    for p in outputs:
        assert mocycle.read(tmp_path / p) is not None  # a whole file mocycle reads back
    assert (tmp_path / f"walk.{command}.json").exists()


def test_a_take_that_fails_part_way_leaves_none_of_its_outputs(tmp_path, short_walk, monkeypatch):
    import mocycle.batch.take as take_module
    import mocycle.io

    out = tmp_path / "out"
    monkeypatch.setattr(take_module, "motion_targets", lambda report, target: {
        "loop": target, "input": target.with_suffix(".second.bvh")})  # two motions to write
    real_write = mocycle.io.write

    def write(obj, path):
        if "second" in str(path):
            raise OSError(28, "No space left on device")
        return real_write(obj, path)

    monkeypatch.setattr(mocycle.io, "write", write)
    row = process(_job(tmp_path), _take(short_walk))
    assert row["status"] == "error" and "No space left on device" in row["message"]
    assert sorted(p.name for p in out.iterdir()) == ["walk.loop.json"]  # the first loop went too
