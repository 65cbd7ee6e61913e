import json

import numpy as np
from typer.testing import CliRunner

from mocycle.cli import app
from mocycle.datasets import synthetic_still, synthetic_walk
from mocycle.io import read, write

runner = CliRunner()


def _walk(tmp_path, n=400):
    return write(synthetic_walk(n_frames=n, noise_deg=1.0).motion, tmp_path / "walk.bvh")


def test_loop_json_and_bvh(tmp_path):
    src = _walk(tmp_path)
    out = tmp_path / "cycle.bvh"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json", "--cycles", "3", "--root", "motion"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    for key in ("period_frames", "n_periods", "method", "model", "metrics", "seconds"):
        assert key in facts
    assert abs(facts["period_frames"] - 60) < 1 and facts["method"] == "harmonic" and facts["model"] == "M1"
    cycle = read(out)
    assert cycle.n_frames == 3 * facts["cycle_frames"] and np.isclose(cycle.fps, 60)
    assert cycle.root_positions[-1, 2] - cycle.root_positions[0, 2] > 2.5 * 130  # walks on


def test_loop_table_plot_and_other_methods(tmp_path):
    src = _walk(tmp_path, 300)
    for method in ("centroid", "cut"):
        out, png = tmp_path / f"{method}.bvh", tmp_path / f"{method}.png"
        result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--method", method, "--plot", str(png),
                                     "--range", "20:", "--joints", "legs"])
        assert result.exit_code == 0, result.output
        assert "seam jump" in result.output and out.exists() and png.stat().st_size > 10_000


def test_no_periodic_motion_exits_3_and_writes_nothing(tmp_path):
    src = write(synthetic_still(noise_deg=0.5).motion, tmp_path / "still.bvh")
    out = tmp_path / "cycle.bvh"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out)])
    assert result.exit_code == 3
    assert "no repeating motion: the actor stands still" in result.stderr  # plain words on the terminal
    assert not out.exists()
    as_json = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json"])
    facts = json.loads(as_json.stdout)  # a refused take prints its JSON too: status, reason, the technical why
    assert as_json.exit_code == 3 and facts["status"] == "no-periodic-motion" and facts["loops"] == []
    assert [p["kind"] for p in facts["parts"]] == ["standing"] and facts["not_looped"][0]["reason"]


def test_bad_options_exit_2_with_one_message(tmp_path):
    src = _walk(tmp_path, 200)
    cases = [  # a bad value exits 2 (usage); too many harmonics for the take's one part is that part's failure: 3
        (["--harmonics", "80"], "K must be <=", 3),
        (["--harmonics", "many"], "--harmonics must be", 2),
        (["--model", "M7"], "--model must be one of", 2),
        (["--method", "spline"], "--method must be one of harmonic, centroid, cut", 2),
        (["--root", "flying"], "--root must be one of", 2),
        (["--cycles", "0"], "--cycles must be a positive integer", 2),
        (["--range", "150:100"], "outside the take", 2),
    ]
    for extra, message, code in cases:
        out = tmp_path / "x.bvh"
        result = runner.invoke(app, ["loop", str(src), "-o", str(out)] + extra)
        assert result.exit_code == code, (extra, result.output)
        assert message in result.stderr and result.stderr.count("error:") == 1, (extra, result.stderr)
        assert not out.exists()
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "x.txt")])
    assert result.exit_code == 1 and "must name a .bvh or .glb file" in result.stderr
    result = runner.invoke(app, ["loop", str(tmp_path / "missing.bvh"), "-o", str(tmp_path / "x.bvh")])
    assert result.exit_code == 1 and "missing.bvh" in result.stderr


def test_demo_writes_the_take_the_cycle_and_the_plot(tmp_path):
    result = runner.invoke(app, ["demo", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    for name in ("synthetic_walk.bvh", "walk_cycle.bvh", "walk_cycle_x4.bvh", "walk_cycle.png"):
        assert (tmp_path / name).exists(), name
    assert "periods of" in result.output


def test_loop_part_all_writes_one_file_per_part(tmp_path):
    from mocycle.datasets import synthetic_walk_then_run

    take = synthetic_walk_then_run(n_walk=150, n_run=150, fps=30.0, noise_deg=1.0, seed=1)
    src = write(take.motion, tmp_path / "walk_run.bvh")
    out = tmp_path / "loop.bvh"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--part", "all", "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    loops = facts["loops"]
    assert [f["kind"] for f in loops] == ["walk straight", "run straight"]
    walk, run = loops
    k = run["part"]  # the index into the JSON's parts (the steps where the walk becomes a run may be one)
    assert facts["parts"][k]["kind"] == "run straight" and walk["part"] == 0
    assert [f["output"] for f in loops] == [str(tmp_path / "loop.part0-walk-straight.bvh"),
                                            str(tmp_path / f"loop.part{k}-run-straight.bvh")]
    assert not out.exists()
    assert abs(walk["period_frames"] - 30) < 1 and abs(run["period_frames"] - 21) < 1
    assert walk["frames"][1] <= 150 + 0.5 * 21 and run["frames"][0] >= 150 - 0.5 * 30  # each from its own part
    assert read(tmp_path / f"loop.part{k}-run-straight.bvh").n_frames == run["cycle_frames"]
    for f in loops:
        assert f["joints_used"] == "legs" and f["period_source"] in f["period_candidates"]
    text = runner.invoke(app, ["loop", str(src), "-o", str(out), "--class", str(k)])  # --class: the old name
    assert text.exit_code == 0 and f"part {k} (run straight" in text.output and out.exists()
    assert "--class is deprecated" in text.stderr and "--part" in text.stderr
    for bad in ("two", "-1", "9"):
        refused = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "x.bvh"), "--part", bad])
        assert refused.exit_code == 2 and "--part" in refused.stderr  # a bad option value: usage error


def test_loop_takes_the_phase_options_and_reports_the_period_decision(tmp_path):
    src = _walk(tmp_path, 300)
    out = tmp_path / "cycle.bvh"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json", "--pca", "6", "--delay", "1",
                                 "--joints", "legs", "--classes", "1", "--min-periods", "1.5"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    # the phase asked for: the cohomology on the legs inside the walk's one part, not its strides
    assert facts["joints_used"] == "legs" and abs(facts["legs_period_frames"] - 60) < 1.5
    assert facts["half_cycle_doubled"] is False and "cohomology" in facts["period_candidates"]
    assert [p["kind"] for p in facts["parts"]] == ["walk straight"] and facts["part"] == 0
    for bad, message in ((["--min-periods", "0.5"], "--min-periods"), (["--delay", "-1"], "--delay")):
        refused = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "x.bvh"), *bad])
        assert refused.exit_code == 2 and message in refused.stderr  # a bad option value: usage error
    too_many = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "y.bvh"), "--min-periods", "9"])
    assert too_many.exit_code == 3 and not (tmp_path / "y.bvh").exists()
