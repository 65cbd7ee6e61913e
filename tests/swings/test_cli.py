import json

import pytest
from typer.testing import CliRunner

import mocycle.cli.swings  # noqa: F401  (registers the command)
from mocycle.cli import app
from mocycle.datasets import synthetic_run, synthetic_walk
from mocycle.io import read_bvh, write_bvh

runner = CliRunner()


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    return write_bvh(synthetic_walk(n_frames=240, fps=60, seed=1).motion, d / "walk.bvh")


def test_help():
    for cmd in ("swings", "search", "edit"):
        r = runner.invoke(app, [cmd, "--help"])
        assert r.exit_code == 0 and "Usage" in r.output


def test_swings_json_and_outputs(walk_file, tmp_path):
    r = runner.invoke(app, ["swings", str(walk_file), "--json", "-o", str(tmp_path / "s.json"),
                            "--playback", str(tmp_path / "pb.bvh"), "--plot", str(tmp_path / "s.png")])
    assert r.exit_code == 0, r.output
    facts = json.loads(r.stdout)
    assert set(facts) == {"joints", "n_swings", "segmentation_error", "per_angle_error_deg", "geodesic_error_deg",
                          "compressed_bytes", "raw_float32_bytes", "swing_indices", "seconds"}
    assert facts["n_swings"] > 10 and "LeftUpLeg" in facts["joints"]
    assert facts["swing_indices"]["LeftUpLeg"].startswith("0-")  # what edit --swing takes
    assert facts["compressed_bytes"] < facts["raw_float32_bytes"] / 4
    assert json.loads((tmp_path / "s.json").read_text())["n_swings"] == facts["n_swings"]
    assert read_bvh(tmp_path / "pb.bvh").n_frames == 240
    assert (tmp_path / "s.png").read_bytes()[:4] == b"\x89PNG"


def test_swings_mosw_round_trip_and_table(walk_file, tmp_path):
    r = runner.invoke(app, ["swings", str(walk_file), "--threshold", "0.6", "-o", str(tmp_path / "s.mosw")])
    assert r.exit_code == 0, r.output
    assert "Segmentation Error" in r.output and "LeftUpLeg" in r.output
    assert "indices" in r.output and "edit --swing" in r.output and "wrote " + str(tmp_path / "s.mosw") in r.output
    assert "time " in r.output
    r = runner.invoke(app, ["swings", str(tmp_path / "s.mosw"), "--json", "--playback", str(tmp_path / "b.bvh")])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["segmentation_error"] is None and read_bvh(tmp_path / "b.bvh").n_frames == 240


@pytest.mark.parametrize("args, word, code", [(["--threshold", "3"], "--threshold must be a number in [0, 2]", 2),
                                              (["-o", "x.txt"], ".mosw or .json", 1),
                                              (["--joints", "Tail"], "Tail", 1)])
def test_swings_bad_options(walk_file, args, word, code):
    r = runner.invoke(app, ["swings", str(walk_file), *args])
    assert r.exit_code == code and word in r.output and "error:" in r.output


def test_search_ranks_a_folder(tmp_path):
    for k in range(2):
        write_bvh(synthetic_walk(n_frames=180, fps=60, seed=k).motion, tmp_path / f"walk{k}.bvh")
        write_bvh(synthetic_run(n_frames=180, fps=60, seed=k).motion, tmp_path / f"run{k}.bvh")
    r = runner.invoke(app, ["search", str(tmp_path / "walk0.bvh"), str(tmp_path), "--top", "2", "--json"])
    assert r.exit_code == 0, r.output
    res = json.loads(r.stdout)["results"]
    assert [x["rank"] for x in res] == [1, 2] and res[0]["path"].endswith("walk1.bvh")
    assert res[0]["score"] >= res[1]["score"]
    r = runner.invoke(app, ["search", str(tmp_path / "walk0.bvh"), str(tmp_path)])
    assert r.exit_code == 0 and "walk1.bvh" in r.output and "run0.bvh" in r.output
    r = runner.invoke(app, ["search", str(tmp_path / "walk0.bvh"), str(tmp_path / "none")])
    assert r.exit_code == 1 and "not a folder" in r.output


def test_edit_writes_the_edited_motion(walk_file, tmp_path):
    out = tmp_path / "e.bvh"
    r = runner.invoke(app, ["edit", str(walk_file), "--joint", "LeftUpLeg", "--swing", "1", "--angle-scale", "1.5",
                            "-o", str(out), "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["joint"] == "LeftUpLeg" and read_bvh(out).n_frames == 240
    r = runner.invoke(app, ["edit", str(walk_file), "--joint", "LeftUpLeg", "--swing", "999", "-o", str(out)])
    assert r.exit_code == 1 and "swings" in r.output
    r = runner.invoke(app, ["edit", str(walk_file), "--joint", "LeftUpLeg", "--swing", "0", "-o", "x.png"])
    assert r.exit_code == 1 and ".bvh" in r.output
