"""glTF output: the Khronos validator accepts every file, and three.js (GLTFLoader + AnimationMixer, in node)
plays the clip to the joint positions of mocycle's own forward kinematics.

The JavaScript side is ``tests/js/check_glb.mjs``; its packages (``gltf-validator``, ``three``) are installed
by ``make js`` (``npm ci`` in tests/js), which ``make test`` runs first.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import mocycle
from conftest import shared_path
from helpers import random_motion
from mocycle.cli import app
from mocycle.datasets import synthetic_circle_walk, synthetic_walk, to_z_up
from mocycle.errors import MocycleError, MotionFileError
from mocycle.io.gltf import UNITS, gltf_frame, write_gltf
from mocycle.motion import EndSite, Motion, Skeleton
from mocycle.rotations import slerp

pygltflib = pytest.importorskip("pygltflib")

JS = Path(__file__).resolve().parents[1] / "js"
TOLERANCE = 1e-4  # joint positions, relative to the body's size
runner = CliRunner()


def run_js(path: Path, times) -> dict:
    """``check_glb.mjs`` on ``path``: the validator's report and the node world positions at ``times`` (s)."""
    node = shutil.which("node")
    if node is None:
        pytest.fail("the glTF tests need node (Node.js 18 or later) on the PATH")
    if not (JS / "node_modules" / "three").is_dir() or not (JS / "node_modules" / "gltf-validator").is_dir():
        pytest.fail(f"{JS}/node_modules is missing: run `make js` (npm ci in tests/js) before the tests")
    out = subprocess.run([node, str(JS / "check_glb.mjs"), str(path), *(repr(float(t)) for t in times)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def assert_valid(report: dict) -> None:
    v = report["validator"]
    assert v["numErrors"] == 0 and v["numWarnings"] == 0, json.dumps(v["messages"], indent=1)


def fk_error(report: dict, motion: Motion, frames, scale="auto", up=None) -> float:
    """Largest distance between three.js's node positions and mocycle's FK at ``frames`` (one per time asked
    for), relative to the body's size; nodes are the joints, then the End Sites (the writer's order)."""
    frame = gltf_frame(motion, scale, up)
    size = frame.body_size * frame.scale
    worst = 0.0
    for positions, k in zip(report["positions"], frames, strict=True):
        fk = frame.point(k.world_positions(end_sites=True)[0] if isinstance(k, Motion)
                         else motion.world_positions(end_sites=True)[k])
        js = np.array([positions[str(i)] for i in range(fk.shape[0])])
        worst = max(worst, float(np.abs(js - fk).max()) / size)
    return worst


def between(motion: Motion, k: int, u: float) -> Motion:
    """The pose a fraction ``u`` of the way from frame ``k`` to ``k + 1``: rotations slerped, translations
    lerped, as glTF's LINEAR interpolation defines it."""
    q = slerp(motion.rotations[k], motion.rotations[k + 1], np.full(motion.n_joints, u))
    t = (1 - u) * motion.translations[k] + u * motion.translations[k + 1]
    return Motion(motion.skeleton, q[None], t[None], motion.frame_time)


def scaled(motion: Motion, factor: float) -> Motion:
    """``motion`` with every length times ``factor`` (another unit)."""
    sk = motion.skeleton
    sites = [EndSite(s.parent, tuple(np.multiply(s.offset, factor)), s.name) for s in sk.end_sites]
    return motion.replace(skeleton=Skeleton(sk.names, sk.parents, sk.offsets * factor, sk.channels, sites),
                          translations=motion.translations * factor)


def glb_json(path: Path) -> dict:
    return json.loads(pygltflib.GLTF2.load(str(path)).to_json())


# ------------------------------------------------------------------------------------------------- the writer
@pytest.mark.parametrize("case", ["walk", "z-up walk", "names with spaces, full turns"])
def test_three_plays_what_mocycle_computes(tmp_path, case):
    motion = {"walk": lambda: synthetic_walk(n_frames=90).motion,
              "z-up walk": lambda: to_z_up(synthetic_walk(n_frames=90).motion),
              "names with spaces, full turns": lambda: random_motion(90, spin=True)}[case]()
    path = write_gltf(motion, tmp_path / "take.glb")
    frames = [0, 1, 33, motion.n_frames - 1]
    report = run_js(path, [k * motion.frame_time for k in frames] + [33.25 * motion.frame_time])
    assert_valid(report)
    assert report["clip"]["name"] == "take"
    assert report["clip"]["duration"] == pytest.approx((motion.n_frames - 1) * motion.frame_time, rel=1e-6)
    assert report["bones"] == motion.n_joints + len(motion.skeleton.end_sites)
    assert report["skinnedMeshes"] == 1
    error = fk_error(report, motion, frames + [between(motion, 33, 0.25)])
    assert error <= TOLERANCE, error


def test_many_joints_and_a_single_frame(tmp_path):
    """Over 256 joints (16-bit joint indices in the mesh) and a one-frame motion are valid glTF too."""
    from scipy.spatial.transform import Rotation

    n = 300
    chain = Skeleton([f"j{i}" for i in range(n)], [-1, *range(n - 1)], np.tile([0.0, 0.6, 0.0], (n, 1)),
                     [("Zrotation", "Xrotation", "Yrotation")] * n)
    q = Rotation.from_rotvec(np.random.default_rng(0).normal(size=(4 * n, 3)) * 0.02).as_quat().reshape(4, n, 4)
    motion = Motion(chain, q, None, 1 / 30)
    report = run_js(write_gltf(motion, tmp_path / "chain.glb"), [0.0, 0.05])
    assert_valid(report)
    assert report["bones"] == n and fk_error(report, motion, [0, between(motion, 1, 0.5)]) <= TOLERANCE
    one = synthetic_walk(n_frames=30).motion[5:6]
    report = run_js(write_gltf(one, tmp_path / "one.glb"), [0.0])
    assert_valid(report)
    assert report["clip"]["duration"] == 0 and fk_error(report, one, [0]) <= TOLERANCE


def test_units_and_axes(tmp_path):
    walk = synthetic_walk(n_frames=30).motion  # centimetres, Y up
    assert gltf_frame(walk).unit == "cm"
    tall = gltf_frame(walk).body_size * 0.01
    assert 1.5 < tall < 2.0
    z = gltf_frame(to_z_up(walk))
    assert z.rotation @ np.array([0, 0, 1.0]) == pytest.approx([0, 1, 0])  # Z up -> glTF Y up
    assert z.rotation @ np.array([0, -1, 0.0]) == pytest.approx([0, 0, 1])  # a Z-up -Y front faces +Z
    assert gltf_frame(walk, up="-y").rotation @ np.array([0, -1, 0.0]) == pytest.approx([0, 1, 0])
    assert gltf_frame(walk, scale="in").scale == UNITS["in"] and gltf_frame(walk, scale=0.5).scale == 0.5
    assert gltf_frame(scaled(walk, 0.01)).unit == "m"
    assert gltf_frame(scaled(walk, 0.01 / 0.0254)).unit == "in"
    assert gltf_frame(scaled(walk, 0.01 / UNITS["cmu"])).unit == "cmu"
    assert gltf_frame(scaled(walk, 10)).unit == "mm"
    # Bandai's rig: a static joint_Root at the room's origin above the Hips, which walk 4 m away
    sk = walk.skeleton
    rooted = Skeleton(("joint_Root", *sk.names), [-1, *(sk.parents + 1)], np.vstack([[0, 0, 0], sk.offsets]),
                      [("Xposition", "Yposition", "Zposition"), *sk.channels],
                      [EndSite(e.parent + 1, e.offset, e.name) for e in sk.end_sites])
    q = np.concatenate([np.tile([0, 0, 0, 1.0], (walk.n_frames, 1, 1)), walk.rotations], axis=1)
    t = np.concatenate([np.zeros((walk.n_frames, 1, 3)), walk.translations], axis=1)
    t[:, 1] += [400.0, 0, 0]
    far = Motion(rooted, q, t, walk.frame_time)
    assert gltf_frame(far).body_size == pytest.approx(gltf_frame(walk).body_size)
    # one or two frames cannot show which joint travels: the body's root (the Hips, where the skeleton
    # branches) is taken, not the static joint_Root 4 m away (the one-frame take was 457 units tall, lying on -Z)
    for n in (1, 2):
        few = far[:n]
        with warnings.catch_warnings():
            warnings.simplefilter("error", mocycle.MocycleWarning)  # no "the body is ... units tall"
            frame = gltf_frame(few)
        assert few.travel_joint == 1 and frame.unit == "cm" and frame.up.tolist() == [0.0, 1.0, 0.0]
        assert frame.body_size == pytest.approx(gltf_frame(walk[:n]).body_size)
        assert 150 < frame.body_size < 200
    # the node positions the file holds are in metres, Y up: the hips stand about 1 m high
    js = run_js(write_gltf(to_z_up(walk), tmp_path / "z.glb"), [0.0])
    assert 0.7 < js["positions"][0]["0"][1] < 1.2
    with pytest.raises(MocycleError, match="gltf_scale"):
        gltf_frame(walk, scale="furlongs")
    with pytest.raises(MocycleError, match="gltf_up"):
        gltf_frame(walk, up="w")


def test_the_declared_unit_wins_and_a_moving_ik_target_is_no_body():
    """A file's declared unit is the GLB's, whatever the body measures (the same for every take of a file); a
    leaf IK target that moves first (RobotExpressive's feet, under the root beside the body) was taken for the
    body: 0 units tall."""
    walk = synthetic_walk(n_frames=30).motion
    sk = walk.skeleton

    def declared(unit):
        return Motion(Skeleton(sk.names, sk.parents, sk.offsets, sk.channels, sk.end_sites, metres_per_unit=unit),
                      walk.rotations, walk.translations, walk.frame_time)

    assert gltf_frame(declared(0.01)).unit == "cm"
    with warnings.catch_warnings():
        warnings.simplefilter("error", mocycle.MocycleWarning)  # the file says metres: a 170 m body, no guess
        frame = gltf_frame(declared(1.0))
    assert frame.unit == "m" and frame.scale == 1.0
    assert (gltf_frame(declared(0.02)).unit, gltf_frame(declared(0.02)).scale) == ("file", 0.02)
    assert gltf_frame(declared(0.02), scale="cm").scale == 0.01  # an override still wins
    six = ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")
    rig = Skeleton(("Bone", "FootIK", *sk.names), [-1, 0, 0, *(sk.parents[1:] + 2)],
                   np.vstack([[0, 0, 0], [10, 0, 0], sk.offsets]), [six, six, *sk.channels],
                   [EndSite(e.parent + 2, e.offset, e.name) for e in sk.end_sites])
    T = walk.n_frames
    q = np.concatenate([np.tile([0, 0, 0, 1.0], (T, 2, 1)), walk.rotations], axis=1)
    t = np.concatenate([np.zeros((T, 2, 3)), walk.translations], axis=1)
    t[:, 1, 2] = np.linspace(0, 30, T)  # the IK target slides
    ik = Motion(rig, q, t, walk.frame_time)
    assert ik.travel_joint == 1
    assert gltf_frame(ik).body_size > 0.9 * gltf_frame(walk).body_size


def test_a_body_of_no_known_unit_is_warned_about():
    walk = synthetic_walk(n_frames=30).motion
    with pytest.warns(mocycle.MocycleWarning, match="option 'gltf_scale'"):
        gltf_frame(scaled(walk, 1e4))


def test_translation_channels_only_where_the_translation_moves(tmp_path):
    walk = synthetic_walk(n_frames=30).motion
    gl = glb_json(write_gltf(walk, tmp_path / "w.glb"))
    paths = [(c["target"]["node"], c["target"]["path"]) for c in gl["animations"][0]["channels"]]
    assert sorted(n for n, p in paths if p == "rotation") == list(range(walk.n_joints))
    assert [n for n, p in paths if p == "translation"] == [walk.travel_joint]
    assert gl["animations"][0]["samplers"][0]["interpolation"] == "LINEAR"


def test_write_dispatch(tmp_path):
    walk = synthetic_walk(n_frames=30).motion
    path = mocycle.write(walk, tmp_path / "walk.glb", clip="stroll")
    assert path.read_bytes()[:4] == b"glTF"
    assert glb_json(path)["animations"][0]["name"] == "stroll"
    from mocycle.keyframes import compress

    with pytest.raises(MotionFileError, match="Compressed"):
        mocycle.write(compress(walk), tmp_path / "walk2.glb")
    assert not (tmp_path / "walk2.glb").exists()
    assert mocycle.read(path).n_frames == walk.n_frames  # glTF is read too (issue 31)


# ------------------------------------------------------------------------------------------------------ loops
@pytest.mark.parametrize("up", ["y", "z"])
def test_turning_root_motion_loop(tmp_path, up):
    take = synthetic_circle_walk(n_frames=480, turn_per_cycle_deg=45.0, up=up).motion
    src = mocycle.write(take, tmp_path / "circle.bvh")
    out = tmp_path / "circle.glb"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--root", "motion", "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    n = facts["cycle_frames"]
    assert facts["closing_frame"] is True and facts["frames_out"] == n + 1
    report = mocycle.tasks.loop.run(src, mocycle.tasks.loop.Options(root="motion"))
    from mocycle.tasks.clips import closed_loop

    written = closed_loop(report.result, 1, "motion")
    js = run_js(out, [k * take.frame_time for k in (0, n // 3, n - 1, n)])
    assert_valid(js)
    assert js["clip"]["name"] == "circle_loop"
    assert js["clip"]["duration"] == pytest.approx(n * take.frame_time, rel=1e-6)  # one whole period
    assert fk_error(js, written, [0, n // 3, n - 1, n]) <= TOLERANCE
    # the closing key is frame 0 moved on by one cycle: turned by the turn per cycle about the vertical
    frame = gltf_frame(written)
    hips = frame.point(written.world_positions()[[0, n], 0])
    meta = js["sceneExtras"]["mocycle"]["clips"][0]
    assert meta["loopable"] and meta["root_motion"] and not meta["in_place"] and meta["closing_frame"]
    assert abs(meta["turn_per_cycle_deg"]) == pytest.approx(45.0, abs=3.0)
    assert np.allclose(np.asarray(meta["travel_per_cycle"])[[0, 2]], (hips[1] - hips[0])[[0, 2]], atol=2e-3)
    assert meta["cycle_frames"] == n and meta["cycle_seconds"] == pytest.approx(n * take.frame_time)
    assert js["sceneExtras"]["mocycle"]["units"]["unit"] == "cm"
    gl = glb_json(out)
    assert gl["animations"][0]["extras"]["name"] == "circle_loop"


def test_in_place_loop_closing_frame_options(tmp_path):
    src = mocycle.write(synthetic_walk(n_frames=300).motion, tmp_path / "walk.bvh")
    for extra, keys in (([], 61), (["--no-closing-frame"], 60)):
        out = tmp_path / f"walk{keys}.glb"
        result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json", *extra])
        assert result.exit_code == 0, result.output
        facts = json.loads(result.stdout)
        gl = glb_json(out)
        times = gl["accessors"][gl["animations"][0]["samplers"][0]["input"]]
        assert times["count"] == keys == facts["frames_out"]
        meta = gl["animations"][0]["extras"]
        assert meta["in_place"] and meta["closing_frame"] == (keys == 61) and meta["name"] == f"walk{keys}_loop"
    bvh = tmp_path / "walk.closed.bvh"
    assert runner.invoke(app, ["loop", str(src), "-o", str(bvh), "--closing-frame"]).exit_code == 0
    closed = mocycle.read(bvh)
    assert closed.n_frames == 61
    assert np.abs(closed.world_positions()[-1] - closed.world_positions()[0]).max() < 1e-3  # frame N = frame 0
    assert mocycle.read(mocycle.write(closed, tmp_path / "x.bvh")).n_frames == 61
    plain = tmp_path / "walk.plain.bvh"
    assert runner.invoke(app, ["loop", str(src), "-o", str(plain)]).exit_code == 0
    assert mocycle.read(plain).n_frames == 60  # BVH loops keep no closing frame unless asked


def test_loop_all_classes_write_one_glb_each(tmp_path):
    from mocycle.datasets import synthetic_walk_then_run

    take = synthetic_walk_then_run(n_walk=150, n_run=150, fps=30.0, noise_deg=1.0, seed=1)
    src = mocycle.write(take.motion, tmp_path / "wr.bvh")
    out = tmp_path / "wr.glb"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--part", "all", "--json"])
    assert result.exit_code == 0, result.output
    loops = json.loads(result.stdout)["loops"]
    assert [f["kind"] for f in loops] == ["walk straight", "run straight"]
    for f in loops:
        gl = glb_json(Path(f["output"]))
        assert Path(f["output"]).suffix == ".glb"
        assert gl["animations"][0]["name"] == f"wr.part{f['part']}-{f['kind'].replace(' ', '-')}_loop"


# ------------------------------------------------------------------------------------------ every command
def test_every_command_that_writes_motion_writes_glb(tmp_path):
    walk = synthetic_walk(n_frames=300).motion
    src = mocycle.write(walk, tmp_path / "walk.bvh")
    src2 = mocycle.write(synthetic_walk(n_frames=300, period_s=0.8).motion, tmp_path / "walk2.bvh")
    mck = tmp_path / "walk.mck"
    assert runner.invoke(app, ["compress", str(src), "-o", str(mck)]).exit_code == 0
    o = str(tmp_path / "out.glb")
    commands = {
        "loop": ["loop", str(src), "-o", o],
        "blend": ["blend", str(src), str(src2), "-o", o],
        "transition": ["transition", str(src), str(src2), "-o", o, "--cycles", "2"],
        "stretch": ["stretch", str(src), "--factor", "1.5", "-o", o],
        "decompress": ["decompress", str(mck), "-o", o],
        "convert": ["convert", str(src), o],
        "edit": ["edit", str(src), "--joint", "LeftUpLeg", "--swing", "1", "--angle-scale", "1.2", "-o", o],
        "swings --playback": ["swings", str(src), "--playback", o],
    }
    for name, args in commands.items():
        Path(o).unlink(missing_ok=True)
        result = runner.invoke(app, args)
        assert result.exit_code == 0, (name, result.output)
        gl = glb_json(Path(o))
        clip = gl["animations"][0]["name"]
        assert clip == ("out_loop" if name in ("loop", "blend") else "out"), name
        assert gl["animations"][0]["extras"]["loopable"] == (name in ("loop", "blend")), name
    js = run_js(Path(o), [0.0])
    assert_valid(js)


def test_bad_gltf_options_are_usage_errors_and_write_nothing(tmp_path):
    src = mocycle.write(synthetic_walk(n_frames=120).motion, tmp_path / "walk.bvh")
    out = tmp_path / "x.glb"
    for extra, flag in ((["--gltf-scale", "huge"], "--gltf-scale"), (["--gltf-scale", "-1"], "--gltf-scale"),
                        (["--gltf-up", "w"], "--gltf-up")):
        result = runner.invoke(app, ["convert", str(src), str(out), *extra])
        assert result.exit_code == 2 and flag in result.stderr, (extra, result.output)
        assert not out.exists()
    result = runner.invoke(app, ["convert", str(src), str(out), "--gltf-scale", "0.01", "--gltf-up", "y"])
    assert result.exit_code == 0, result.output
    assert glb_json(out)["scenes"][0]["extras"]["mocycle"]["units"]["metres_per_unit"] == 0.01


# -------------------------------------------------------------------------------------------- real captures
REAL = [("cmu", "01_01.bvh", "cmu"), ("cmu", "01_01.amc", "cmu"), ("cmu-iclone", "02_01.bvh", "cm"),
        ("bandai", "dataset-1_walk_normal_001.bvh", "cm")]


@pytest.mark.shared_data
@pytest.mark.parametrize("folder, name, unit", REAL, ids=[r[1] for r in REAL])
def test_real_takes(tmp_path, folder, name, unit):
    motion = mocycle.read(shared_path(folder, name))[:400]
    assert gltf_frame(motion).unit == unit
    path = write_gltf(motion, tmp_path / "take.glb")
    frames = [0, 150, motion.n_frames - 1]
    report = run_js(path, [k * motion.frame_time for k in frames])
    assert_valid(report)
    assert report["bones"] == motion.n_joints + len(motion.skeleton.end_sites)
    assert fk_error(report, motion, frames) <= TOLERANCE


@pytest.mark.shared_data
def test_real_root_motion_loop(tmp_path):
    src = shared_path("bandai", "dataset-1_walk_normal_001.bvh")
    out = tmp_path / "walk.glb"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--root", "motion", "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    n = facts["cycle_frames"]
    js = run_js(out, [0.0, n / facts["fps"]])
    assert_valid(js)
    meta = js["sceneExtras"]["mocycle"]["clips"][0]
    assert meta["root_motion"] and meta["travel_joint"] == "Hips"
    assert np.linalg.norm(meta["travel_per_cycle"]) == pytest.approx(np.linalg.norm(facts["travel_per_cycle"])
                                                                     * 0.01, rel=1e-6)
    if facts["feet"]["mode"] == "lock":
        assert set(meta["foot_contacts"]) == set(facts["feet"]["contacts"])


def test_without_pygltflib_one_clear_error_before_any_work(tmp_path, monkeypatch):
    import importlib.util
    import sys

    src = mocycle.write(synthetic_walk(n_frames=120).motion, tmp_path / "walk.bvh")
    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pygltflib" else
                        find_spec(name, *a))
    ran = []
    monkeypatch.setattr(mocycle.tasks.loop, "run", lambda *a, **k: ran.append(1))
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "x.glb")])
    assert result.exit_code == 1 and "pip install 'mocycle[gltf]'" in result.stderr
    assert not ran and not (tmp_path / "x.glb").exists()
    monkeypatch.setitem(sys.modules, "pygltflib", None)  # import pygltflib fails
    with pytest.raises(MocycleError, match=r"mocycle\[gltf\]"):
        mocycle.write(mocycle.read(src), tmp_path / "y.glb")
    assert not (tmp_path / "y.glb").exists()
