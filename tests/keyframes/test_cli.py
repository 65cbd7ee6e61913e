import json

import numpy as np
import pytest
from typer.testing import CliRunner

import mocycle.cli.keyframes  # noqa: F401  (registers the command)
from helpers import max_angle
from mocycle.cli import app
from mocycle.datasets import synthetic_walk
from mocycle.io import read_bvh, write_bvh

runner = CliRunner()


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("kcli")
    return write_bvh(synthetic_walk(n_frames=240, fps=60, seed=1).motion, d / "walk.bvh")


def test_help():
    for cmd in ("compress", "decompress", "project"):
        r = runner.invoke(app, [cmd, "--help"])
        assert r.exit_code == 0 and "Usage" in r.output


def test_compress_json_then_decompress(walk_file, tmp_path):
    mck = tmp_path / "w.mck"
    r = runner.invoke(app, ["compress", str(walk_file), "-o", str(mck), "--scheme", "spatial", "--projection",
                            "pca", "--optimize", "--select", "scs", "--json"])
    assert r.exit_code == 0, r.output
    facts = json.loads(r.stdout)
    assert set(facts) == {"frames", "keyframes", "error_per_frame_per_joint", "compressed_bytes", "bvh_bytes",
                          "seconds", "ratio", "period_frames", "keys_per_period", "keyframes_set_by"}
    # the default ratio 'auto': 4 keys per 60-frame gait period, not the thesis' 3 % (7 keys, 1.75 per period)
    assert facts["frames"] == 240 and facts["keyframes"] == 17 and facts["ratio"] == "auto"
    assert abs(facts["period_frames"] - 60) < 2 and facts["keys_per_period"] >= 4
    assert facts["keyframes_set_by"] == "rhythm"
    assert facts["compressed_bytes"] == mck.stat().st_size < facts["bvh_bytes"] / 5
    out = tmp_path / "w.bvh"
    r = runner.invoke(app, ["decompress", str(mck), "-o", str(out)])
    assert r.exit_code == 0, r.output
    orig, back = read_bvh(walk_file), read_bvh(out)
    from mocycle.keyframes import read_compressed

    keys = read_compressed(mck).key_idx
    assert back.n_frames == 240 and max_angle(back.rotations[keys], orig.rotations[keys]) < 1e-6
    assert np.allclose(back.translations[keys], orig.translations[keys], atol=1e-6)


def test_compress_table(walk_file, tmp_path):
    r = runner.invoke(app, ["compress", str(walk_file), "-o", str(tmp_path / "a.mck"), "--scheme", "linear"])
    assert r.exit_code == 0, r.output
    assert "error per frame per joint" in r.output and "formula" in r.output


def test_project_plot_and_json(walk_file, tmp_path):
    png = tmp_path / "p.png"
    r = runner.invoke(app, ["project", str(walk_file), "--projection", "rbfp", "--select", "rols", "--optimize",
                            "--plot", str(png), "--json"])
    assert r.exit_code == 0, r.output
    facts = json.loads(r.stdout)
    assert len(facts["points"]) == 240 and facts["keyframes"][0] == 0 and facts["keyframes"][-1] == 239
    assert facts["stress_optimized"] > 0 and png.read_bytes()[:4] == b"\x89PNG"
    r = runner.invoke(app, ["project", str(walk_file)])
    assert r.exit_code == 0 and "stress" in r.output


@pytest.mark.parametrize("args,msg", [
    (["compress", "{f}", "-o", "{d}/x.bvh"], ".mck"),
    (["compress", "{f}", "-o", "{d}/x.mck", "--scheme", "cubic"], "scheme must be"),
    (["compress", "{f}", "-o", "{d}/x.mck", "--ratio", "0"], "ratio must lie"),
    (["decompress", "{f}", "-o", "{d}/x.bvh"], "not a mocycle keyframe file"),
    (["decompress", "{d}/none.mck", "-o", "{d}/x.bvh"], "cannot read"),
    (["project", "{f}", "--projection", "umap"], "projection must be"),
    (["project", "{f}", "--plot", "{d}/x.jpg"], ".png"),
])
def test_errors(walk_file, tmp_path, args, msg):
    args = [a.format(f=walk_file, d=tmp_path) for a in args]
    r = runner.invoke(app, args)
    assert r.exit_code == 1 and msg in r.output
    assert not (tmp_path / "x.bvh").exists() and not (tmp_path / "x.mck").exists()


def test_an_explicit_ratio_that_aliases_the_gait_warns(walk_file, tmp_path):
    r = runner.invoke(app, ["compress", str(walk_file), "-o", str(tmp_path / "w.mck"), "--ratio", "0.03", "--json"])
    assert r.exit_code == 0, r.output
    assert "warning:" in r.output and "per period" in r.output and "--ratio auto" in r.output
    bad = runner.invoke(app, ["compress", str(walk_file), "-o", str(tmp_path / "w.mck"), "--ratio", "x"])
    assert bad.exit_code == 1 and "'auto' or a number" in bad.output
