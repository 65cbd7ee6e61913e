import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import SHARED_DATA, shared_path
from helpers import max_angle, random_motion
from mocycle.errors import MocycleWarning, MotionFileError
from mocycle.io.bvh import format_bvh, motion_channels, one_word_names, parse_bvh, read_bvh, write_bvh

SHARED_BVH = sorted(SHARED_DATA.glob("*/*.bvh")) or [None]  # None: skip with a message


def _round_trip_errors(m, m2):
    ang = max_angle(m.rotations, m2.rotations)
    scale = max(float(np.abs(m.translations).max()), 1e-12)
    rel = float(np.abs(m.translations - m2.translations).max()) / scale
    return ang, rel


def test_round_trip_synthetic_keeps_everything(tmp_path):
    m = random_motion(80, spin=True)
    with pytest.warns(MocycleWarning, match=r"what BVH \(one word each\) can hold"):  # its names hold spaces
        path = write_bvh(m, tmp_path / "m.bvh")
    m2 = read_bvh(path)
    ang, rel = _round_trip_errors(m, m2)
    assert ang < 1e-6 and rel < 1e-6
    joints, sites, _ = one_word_names(m.skeleton)
    assert list(m2.skeleton.names) == joints  # what was written is what is read
    assert m2.skeleton.channels == m.skeleton.channels  # per-joint orders kept
    assert [(s.parent, s.offset, s.name) for s in m2.skeleton.end_sites] == [
        (s.parent, s.offset, name) for s, name in zip(m.skeleton.end_sites, sites, strict=True)
    ]
    assert m2.frame_time == m.frame_time  # exact, not rounded to 6 digits


def test_names_are_written_one_word_each(tmp_path):
    """A whitespace-splitting reader gets one token per joint name: spaces and tabs become underscores, a name
    that would then repeat another gets a number; mocycle reads the names written; said once, as a warning."""
    from mocycle.motion import EndSite, Motion, Skeleton

    rot = ("Zrotation", "Xrotation", "Yrotation")
    skeleton = Skeleton(("Hips", "bras droit", "main\tdroite", "bras_droit"), [-1, 0, 1, 0], np.ones((4, 3)),
                        (("Xposition", "Yposition", "Zposition") + rot, rot, rot, rot),
                        (EndSite(2, (0.0, 1.0, 0.0), "bout du doigt"),))
    m = Motion.rest(skeleton, 3)
    with pytest.warns(MocycleWarning, match=r"3 joint names changed to what BVH \(one word each\) can hold: "
                                            r"'bras droit' -> 'bras_droit.1', 'main\\tdroite' -> 'main_droite', "
                                            r"'bout du doigt' -> 'bout_du_doigt'"):
        path = write_bvh(m, tmp_path / "m.bvh")
    for line in path.read_text().splitlines():
        words = line.split()
        if words and words[0] in ("ROOT", "JOINT"):
            assert len(words) == 2, line
    again = read_bvh(path)
    assert again.skeleton.names == ("Hips", "bras_droit.1", "main_droite", "bras_droit")
    assert again.skeleton.end_sites[0].name == "bout_du_doigt"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_bvh(again, tmp_path / "again.bvh")  # one-word names: nothing to say


def test_written_euler_curves_are_continuous():
    m = random_motion(200, spin=True)  # joint 1 turns five full circles
    values = motion_channels(m)
    assert np.abs(np.diff(values, axis=0))[:, 3:].max() < 60  # degrees per frame, no 360 flips
    text = format_bvh(m)
    assert "Frame Time: 0.016666666666666666" in text


def test_position_channels_on_non_root_joints_survive():
    text = """HIERARCHY
ROOT joint_Root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Hips
  {
    OFFSET 0 93.9 -3
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
1 2 3 10 20 30 4 90 -400 5 6 7
1 2 3 10 20 30 5 91 -401 5 6 7
"""
    m = parse_bvh(text)
    assert np.allclose(m.translations[:, 1], [[4, 90, -400], [5, 91, -401]])
    m2 = parse_bvh(format_bvh(m))
    assert np.allclose(m2.translations, m.translations)
    r = Rotation.from_euler("ZXY", [5, 6, 7], degrees=True)
    assert max_angle(m2.rotations[:, 1], np.tile(r.as_quat(), (2, 1))) < 1e-9


def test_missing_frame_time_and_zero_frame_time_are_errors():
    base = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 1\n"
    with pytest.raises(MotionFileError, match="Frame Time"):
        parse_bvh(base + "1\n", path="x.bvh")
    with pytest.raises(MotionFileError, match=r"x\.bvh:9: Frame Time must be a positive"):
        parse_bvh(base + "Frame Time: 0\n1\n", path="x.bvh")


def test_frames_count_mismatch_warns_and_rows_win():
    text = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 5\nFrame Time: 0.1\n1\n2\n3\n"
    with pytest.warns(UserWarning, match="Frames: 5"):
        m = parse_bvh(text)
    assert m.n_frames == 3


@pytest.mark.parametrize("path", SHARED_BVH, ids=[p.name if p else "absent" for p in SHARED_BVH])
def test_round_trip_shared_files(path, tmp_path):
    if path is None:
        shared_path("cmu", "01_01.bvh")  # skips with the message saying where the data belongs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = read_bvh(path)
        out = write_bvh(m, tmp_path / path.name)
        m2 = read_bvh(out)
    ang, rel = _round_trip_errors(m, m2)
    assert ang < 1e-6, f"rotation differs by {ang} rad"
    assert rel < 1e-6, f"translation differs by {rel} (relative)"
    assert m2.skeleton.channels == m.skeleton.channels
    assert m2.frame_time == m.frame_time
    assert len(m2.skeleton.end_sites) == len(m.skeleton.end_sites)
    # Written Euler curves never flip: where a joint turns less than 20 degrees between
    # frames, our channel steps stay under 180 degrees and no larger than the file's own.
    ours = motion_channels(m2)
    lines = path.read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.lower().startswith("frame time")) + 1
    orig = np.loadtxt(lines[start:], ndmin=2)
    col = 0
    for j, chans in enumerate(m.skeleton.channels):
        cols = [col + k for k, c in enumerate(chans) if "rotation" in c]
        col += len(chans)
        r = Rotation.from_quat(m.rotations[:, j])
        small = np.degrees((r[:-1].inv() * r[1:]).magnitude()) < 20
        if cols and small.any():
            ours_step = np.abs(np.diff(ours[:, cols], axis=0))[small].max()
            file_step = np.abs(np.diff(orig[:, cols], axis=0))[small].max()
            assert ours_step < 180 and ours_step <= file_step + 1e-6, m.skeleton.names[j]


@pytest.mark.parametrize("block", [1, 7, 1024])
def test_read_in_blocks_is_the_motion_of_its_channels(tmp_path, monkeypatch, block):
    """read_bvh normalises and sign-flips block by block (and skips Motion's own pass): bit for bit what
    Motion makes of euler_to_quats' quaternions, with sign flips inside and across blocks."""
    from mocycle.io import bvh_channels
    from mocycle.motion import Motion
    from mocycle.rotations import euler_to_quats

    m = random_motion(200, spin=True)
    values = motion_channels(m)
    rng = np.random.default_rng(1)
    rot_cols = [k for k, c in enumerate(c for chans in m.skeleton.channels for c in chans) if "rotation" in c]
    for frame in rng.choice(200, 40, replace=False):  # a whole turn more: the quaternion's sign flips
        values[frame, rng.choice(rot_cols)] += 360.0
    text = format_bvh(m).split("Frame Time:")[0] + f"Frame Time: {m.frame_time!r}\n"
    path = tmp_path / "flips.bvh"
    path.write_text(text + "\n".join(" ".join(repr(float(v)) for v in row) for row in values) + "\n")
    monkeypatch.setattr(bvh_channels, "BLOCK_FRAMES", block)
    read = read_bvh(path)

    quats = np.empty_like(m.rotations)
    trans = np.broadcast_to(m.skeleton.offsets, m.translations.shape).copy()
    col = 0
    for j, chans in enumerate(m.skeleton.channels):
        rot = [col + k for k, c in enumerate(chans) if "rotation" in c]
        for k, c in enumerate(chans):
            if "position" in c:
                trans[:, j, "XYZ".index(c[0])] = values[:, col + k]
        quats[:, j] = euler_to_quats(values[:, rot], m.skeleton.euler_order(j), degrees=True)
        col += len(chans)
    raw_flips = np.einsum("tjk,tjk->tj", quats[1:], quats[:-1]) < 0
    assert raw_flips.sum() >= 40  # the test flips signs
    expected = Motion(m.skeleton, quats, trans, m.frame_time)
    assert np.array_equal(read.rotations, expected.rotations)
    assert np.array_equal(read.translations, expected.translations)
    assert not read.rotations.flags.writeable and not read.translations.flags.writeable


def test_cmu_bvh_facts():
    m = read_bvh(shared_path("cmu", "01_01.bvh"))
    assert m.n_frames == 2752 and m.n_joints == 31
    assert np.isclose(m.frame_time, 0.0083333)
    assert m.skeleton.euler_order(0) == "ZYX"


def _chain_skeleton(n: int):
    from mocycle.motion import EndSite, Skeleton

    return Skeleton(tuple(f"j{i}" for i in range(n)), list(range(-1, n - 1)), [[0.0, 1.0, 0.0]] * n,
                    (("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),)
                    + (("Zrotation", "Xrotation", "Yrotation"),) * (n - 1), (EndSite(n - 1, (0.0, 1.0, 0.0)),))


def test_deep_hierarchy_writes_and_reads_back_without_recursion(tmp_path):
    import sys

    from mocycle.motion import Motion

    n = sys.getrecursionlimit() + 500  # deeper than any recursive writer could go
    m = Motion.rest(_chain_skeleton(n), 2)
    back = read_bvh(write_bvh(m, tmp_path / "deep.bvh"))
    assert back.skeleton.names == m.skeleton.names
    assert np.array_equal(back.skeleton.parents, m.skeleton.parents)
    assert back.skeleton.end_sites[0].parent == n - 1


def test_writing_holds_one_piece_of_text_at_a_time_not_the_take():
    """``np.savetxt``'s writer keeps its buffer in a reference cycle: each piece's buffer is closed, so the
    memory of writing does not grow with the take (it did until the next garbage collection)."""
    import tracemalloc

    from mocycle.io.bvh import bvh_size

    take = random_motion(16000, seed=3)

    def peak(motion):
        tracemalloc.start()
        try:
            bvh_size(motion)
            return tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    short, long = peak(take[:2000]), peak(take)
    assert long < 1.5 * short, f"writing 16000 frames peaked at {long} bytes, 2000 frames at {short}"


def test_a_deep_chain_is_written_in_linear_size():
    """A 10,000-deep chain once wrote 200 million tabs (its indentation grew with the depth): past MAX_INDENT
    levels every line is indented alike, and the file reads back."""
    from mocycle.io.bvh import MAX_INDENT, format_bvh, parse_bvh
    from mocycle.motion import Motion, Skeleton

    n = 3000
    sk = Skeleton(tuple(f"j{i}" for i in range(n)), np.arange(-1, n - 1), np.tile([0.0, 1.0, 0.0], (n, 1)),
                  (("Zrotation", "Xrotation", "Yrotation"),) * n)
    text = format_bvh(Motion.rest(sk, 2))
    assert max(len(line) - len(line.lstrip("\t")) for line in text.splitlines()) == MAX_INDENT + 1
    assert len(text) < 400 * n  # quadratic indentation: about 18 million characters
    assert parse_bvh(text).n_joints == n
