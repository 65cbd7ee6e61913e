"""The task layer: Options (validation in one place, schema), Reports (JSON round trip, warnings, timings)."""

from __future__ import annotations

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from mocycle import tasks
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk
from mocycle.errors import MocycleError, NoPeriodicMotion, OptionError
from mocycle.io import write
from mocycle.tasks.options import MISSING
from mocycle.tasks.report import Recorder

SRC = Path(tasks.__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=240, fps=60, noise_deg=0.5, seed=1).motion


@pytest.mark.parametrize("name", sorted(tasks.TASKS))
def test_every_task_has_options_run_and_help(name):
    module = tasks.TASKS[name]
    assert callable(module.run) and dataclasses.is_dataclass(module.Options)
    assert module.Options.__dataclass_params__.frozen
    for f in dataclasses.fields(module.Options):
        assert f.metadata.get("help"), f"{name}.{f.name} has no help line"
        assert f.metadata.get("check") is not None, f"{name}.{f.name} is not validated"


@pytest.mark.parametrize("name", sorted(tasks.TASKS))
def test_schema_lists_every_field(name):
    options = tasks.TASKS[name].Options
    s = tasks.schema(options)
    json.dumps(s)  # JSON-ready
    names = [f.name for f in dataclasses.fields(options)]
    assert list(s["properties"]) == names
    assert s["required"] == [f.name for f in dataclasses.fields(options) if f.default is MISSING]
    for f in dataclasses.fields(options):
        prop = s["properties"][f.name]
        assert prop["description"] == f.metadata["help"]
        if f.default is not MISSING:
            assert prop["default"] == f.default


def test_schema_gives_allowed_values_and_ranges():
    s = tasks.schema(tasks.loop.Options)["properties"]
    assert s["method"]["enum"] == ["harmonic", "centroid", "cut"] and s["method"]["default"] == "harmonic"
    assert s["cycles"] == {**s["cycles"], "type": "integer", "minimum": 1}
    assert s["which"]["x-flag"] == "--part" and s["time_axis"]["x-flag"] == "--time"
    assert {"type": "string", "enum": ["auto"]} in s["harmonics"]["anyOf"]
    edit = tasks.schema(tasks.edit.Options)
    assert edit["required"] == ["joint", "swing"]
    assert edit["properties"]["angle_scale"]["minimum"] == 0 and edit["properties"]["angle_scale"]["maximum"] == 10
    assert tasks.schema(tasks.stretch.Options)["properties"]["factor"]["exclusiveMinimum"] == 0


@pytest.mark.parametrize(("options", "kwargs", "parameter"), [
    (tasks.loop.Options, {"method": "spline"}, "method"),
    (tasks.loop.Options, {"cycles": 0}, "cycles"),
    (tasks.loop.Options, {"harmonics": "many"}, "harmonics"),
    (tasks.loop.Options, {"frame_range": "10-20"}, "frame_range"),
    (tasks.phase.Options, {"delay": -1}, "delay"),
    (tasks.blend.Options, {"weights": "0.5,x"}, "weights"),
    (tasks.swings.Options, {"threshold": 3.0}, "threshold"),
    (tasks.search.Options, {"top": 0}, "top"),
    (tasks.compress.Options, {"seed_projection": "lamp"}, "seed_projection"),
    (tasks.project.Options, {"ratio": 0.0}, "ratio"),
    (tasks.info.Options, {"amc_fps": -120}, "amc_fps"),
    (tasks.stretch.Options, {"factor": float("nan")}, "factor"),
])
def test_bad_options_raise_a_value_error_naming_the_parameter(options, kwargs, parameter):
    with pytest.raises(OptionError) as info:
        options(**kwargs)
    assert info.value.parameter == parameter and str(info.value).startswith(parameter)
    assert isinstance(info.value, ValueError) and isinstance(info.value, MocycleError)


def test_options_normalise_and_round_trip():
    o = tasks.loop.Options(harmonics="12", classes="2", cycles=3)
    assert o.harmonics == 12 and o.classes == 2
    assert tasks.loop.Options.from_dict(json.loads(json.dumps(o.to_dict()))) == o
    assert tasks.phase.Options(pca="none").pca is None
    assert tasks.blend.Options(weights="0.7,0.3").weights == (0.7, 0.3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.cycles = 2
    with pytest.raises(OptionError, match="not an option"):
        tasks.loop.Options.from_dict({"cycle": 2})


def test_shared_defaults_are_one_constant():
    assert tasks.AMC_FPS == 120.0 and tasks.SWING_THRESHOLD == 0.4
    for name, module in tasks.TASKS.items():
        for f in dataclasses.fields(module.Options):
            if f.name == "amc_fps":
                assert f.default is tasks.AMC_FPS or f.default == tasks.AMC_FPS, name
    # the literals live in one place each: no 120.0 frame rate or 0.4 threshold typed in the front end or tasks
    for folder in ("cli", "tasks"):
        for path in (SRC / folder).glob("*.py"):
            text = path.read_text()
            assert "= 120.0" not in text and "120.0," not in text, path
            assert "= 0.4," not in text and "= 0.4\n" not in text, path


def test_info_report_round_trips_through_json(walk):
    report = tasks.info.run(walk)
    assert report.task == "info" and report.facts["frames"] == 240 and report.seconds > 0
    back = tasks.Report.from_dict(json.loads(json.dumps(report.to_dict())))
    assert back == report and back.motions == {} and back.result is None
    assert "motions" not in report.to_dict()


def test_loop_report_has_the_figures_the_motion_and_labelled_times(walk):
    report = tasks.loop.run(walk, tasks.loop.Options(cycles=2, root="motion"))
    f = report.facts
    assert abs(f["period_frames"] - 60) < 1.5 and f["cycles"] == 2
    assert report.motions["loop"].n_frames == f["frames_out"] == 2 * f["cycle_frames"]
    assert set(f["metrics"]) >= set(tasks.loop.METRIC_LABELS)
    assert {"total", "cycle", "metrics"} <= set(report.timings_s)
    assert report.timings_s["total"] >= report.timings_s["cycle"] + report.timings_s["metrics"] - 1e-9
    json.dumps(report.to_dict())


def test_tasks_take_files_too(tmp_path, walk):
    path = write(walk, tmp_path / "walk.bvh")
    a, b = tasks.info.run(path), tasks.info.run(walk)
    assert a.facts["frames"] == b.facts["frames"] and np.isclose(a.facts["root_path_length"],
                                                                 b.facts["root_path_length"], rtol=1e-4)


def test_no_periodic_motion_is_refused_and_reported():
    still = synthetic_nonperiodic(n_frames=200, fps=60, seed=3).motion
    assert tasks.phase.run(still).facts["classes"] == []
    with pytest.raises(NoPeriodicMotion):
        tasks.loop.run(still)


def test_blend_checks_weights_against_the_takes(walk):
    with pytest.raises(OptionError, match="weights"):
        tasks.blend.run([walk, walk], tasks.blend.Options(weights=(1.0, 2.0, 3.0)))
    with pytest.raises(OptionError, match="takes"):
        tasks.blend.run([walk])


def test_recorder_keeps_warnings_and_reissues_them_on_error():
    with Recorder() as rec:
        warnings.warn("odd but fine", stacklevel=1)
    assert rec.report("x", {}).warnings == ("odd but fine",)
    with pytest.warns(UserWarning, match="before the error"), pytest.raises(MocycleError):  # noqa: PT012
        with Recorder():
            warnings.warn("before the error", stacklevel=1)
            raise MocycleError("boom")


def test_an_option_shared_by_tasks_accepts_the_same_values_everywhere():
    """(Defaults may differ: transition's --cycles is 3, loop's 1. Listed exceptions: compress's --ratio also
    takes 'auto', project's does not; loop's --class also takes 'all', blend's and transition's do not.)"""
    exceptions = {("compress", "ratio"), ("loop", "which")}
    seen: dict[str, tuple] = {}
    for name, module in tasks.TASKS.items():
        for f in dataclasses.fields(module.Options):
            check = f.metadata["check"]
            constraint = check.schema() if hasattr(check, "schema") else None
            key = constraint
            if (name, f.name) in exceptions:
                continue
            if f.name in seen:
                assert seen[f.name][0] == key, f"{name}.{f.name} differs from {seen[f.name][1]}.{f.name}"
            else:
                seen[f.name] = (key, name)
