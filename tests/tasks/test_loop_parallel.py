"""The parts of a long take looped side by side (issue 38): the same loops, the same bytes, whichever way."""

from __future__ import annotations

import filecmp
import json

import pytest
from cli_json.cases import clean
from typer.testing import CliRunner

from mocycle import tasks
from mocycle.cli import app
from mocycle.datasets import join_takes, synthetic_run, synthetic_walk, synthetic_wave
from mocycle.io import write

runner = CliRunner()


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("parallel")
    takes = [synthetic_walk(n_frames=180, fps=30.0, period_s=1.0, noise_deg=1.0, seed=1).motion,
             synthetic_wave(n_frames=150, fps=30.0, seed=2).motion,
             synthetic_run(n_frames=120, fps=30.0, period_s=0.7, noise_deg=1.0, seed=3).motion,
             synthetic_walk(n_frames=150, fps=30.0, period_s=1.2, noise_deg=1.0, seed=4).motion]
    return write(join_takes(takes, ["walk", "wave", "run", "walk"]).motion, tmp / "session.bvh")


def _run(path, out, *extra):
    out.mkdir()
    result = runner.invoke(app, ["loop", str(path), "-o", str(out / "s.bvh"), "--part", "all", "--root", "motion",
                                 "--json", *extra])
    assert result.exit_code == 0, result.output
    facts = clean(json.loads(result.stdout))  # timing fields dropped, at any depth
    facts.pop("output")
    for loop in facts["loops"]:
        loop.pop("output")
    return facts


def _same_files(a, b) -> bool:
    names = sorted(p.name for p in a.iterdir())
    return names == sorted(p.name for p in b.iterdir()) and all(
        filecmp.cmp(a / n, b / n, shallow=False) for n in names)


def test_two_workers_write_the_same_bytes_as_one(session, tmp_path, monkeypatch):
    monkeypatch.setattr(tasks.loop, "PARALLEL_FRAMES", 0)  # a short take, looped side by side all the same
    one = _run(session, tmp_path / "one", "--workers", "1")
    two = _run(session, tmp_path / "two", "--workers", "2")
    assert len(one["loops"]) >= 4 and one == two
    assert _same_files(tmp_path / "one", tmp_path / "two")


def test_delivered_loops_are_not_kept_in_the_report(session, tmp_path):
    delivered = []

    def deliver(report):
        (role,) = report.motions
        delivered.append(role)
        return {role: (tmp_path / f"{role}.bvh", report.motions[role])}

    report = tasks.loop.run(session, tasks.loop.Options(which="all", root="motion"), deliver=deliver)
    roles = [f["role"] for f in report.facts["loops"]]
    assert delivered == roles and set(report.motions) == {"input"}
    assert all(report.extras[r]["written"][r][1] > 0 for r in roles)


@pytest.mark.slow
def test_a_dask_cluster_writes_the_same_bytes(session, tmp_path):
    distributed = pytest.importorskip("distributed")
    one = _run(session, tmp_path / "one", "--workers", "1")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        two = _run(session, tmp_path / "dask", "--scheduler", c.scheduler_address)
    assert one == two and _same_files(tmp_path / "one", tmp_path / "dask")
