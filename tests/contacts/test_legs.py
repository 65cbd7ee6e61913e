import numpy as np
import pytest

from mocycle.contacts import body_height, find_feet, up_axis
from mocycle.datasets import humanoid_skeleton, synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.motion import Motion, Skeleton
from tests.conftest import shared_files

RIGS = {
    "cmu_asf": {"LeftUpLeg": "lfemur", "LeftLeg": "ltibia", "LeftFoot": "lfoot", "LeftToeBase": "ltoes",
                "RightUpLeg": "rfemur", "RightLeg": "rtibia", "RightFoot": "rfoot", "RightToeBase": "rtoes"},
    "bandai": {"LeftUpLeg": "UpperLeg_L", "LeftLeg": "LowerLeg_L", "LeftFoot": "Foot_L", "LeftToeBase": "Toes_L",
               "RightUpLeg": "UpperLeg_R", "RightLeg": "LowerLeg_R", "RightFoot": "Foot_R",
               "RightToeBase": "Toes_R"},
    "iclone": {n: "CC_Base_" + n.replace("Left", "L_").replace("Right", "R_").replace("UpLeg", "Thigh")
               .replace("Leg", "Calf") for n in ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg",
                                                 "RightLeg", "RightFoot", "RightToeBase")},
    "mixamo": {n: "mixamorig:" + n for n in humanoid_skeleton().names},
}


def _renamed(mapping: dict[str, str]) -> Skeleton:
    s = humanoid_skeleton()
    return Skeleton(tuple(mapping.get(n, n) for n in s.names), s.parents, s.offsets, s.channels, s.end_sites)


@pytest.mark.parametrize("rig", sorted(RIGS))
def test_feet_are_found_on_every_naming(rig):
    skel = _renamed(RIGS[rig])
    left, right = find_feet(skel)
    ref = humanoid_skeleton()
    assert (left.side, right.side) == ("left", "right")
    assert [left.hip, left.knee, left.ankle, left.toe] == [ref.index(n) for n in
                                                           ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase")]
    assert right.ankle == ref.index("RightFoot") and right.toe == ref.index("RightToeBase")


def test_named_feet_and_a_clear_error_when_none_are_found():
    neutral = {n: f"j{i}" for i, n in enumerate(humanoid_skeleton().names)}
    skel = _renamed(neutral)
    with pytest.raises(MocycleError, match="no left and right foot.*option 'foot_joints'"):
        find_feet(skel)
    ankle, toe = neutral["LeftFoot"], neutral["LeftToeBase"]
    feet = find_feet(skel, f"{ankle}:{toe},{neutral['RightFoot']}")
    assert feet[0].ankle == skel.index(ankle) and feet[0].toe == skel.index(toe) and feet[1].toe is None
    with pytest.raises(MocycleError, match="no joint named"):
        find_feet(skel, "nosuchjoint")
    mixamo = _renamed(RIGS["mixamo"])
    feet = find_feet(mixamo, "mixamorig:LeftFoot:mixamorig:LeftToeBase")
    assert feet[0].toe == mixamo.index("mixamorig:LeftToeBase")


def test_up_axis_and_body_height_on_a_z_up_rig():
    m = synthetic_walk(n_frames=120).motion
    assert np.allclose(up_axis(m), [0, 1, 0])
    # turn the whole take so +Z is up: root rotation and translation
    from scipy.spatial.transform import Rotation

    turn = Rotation.from_euler("x", 90, degrees=True)
    q = m.rotations.copy()
    q[:, 0] = (turn * Rotation.from_quat(q[:, 0])).as_quat()
    t = m.translations.copy()
    t[:, 0] = turn.apply(t[:, 0])
    z_up = Motion(m.skeleton, q, t, m.frame_time)
    assert np.allclose(up_axis(z_up), [0, 0, 1])
    assert body_height(z_up) == pytest.approx(body_height(m), rel=1e-9)
    assert 150 < body_height(m) < 190


def test_feet_on_every_shared_rig():
    seen = set()
    for path in shared_files("bandai") + shared_files("cmu-iclone") + shared_files("cmu"):
        m = read(path)
        if m.skeleton.names in seen:
            continue
        seen.add(m.skeleton.names)
        left, right = find_feet(m.skeleton)
        names = [m.skeleton.names[j] for j in (left.ankle, left.toe, right.ankle, right.toe)]
        assert all("foot" in n.lower() or "toe" in n.lower() for n in names), names
        assert np.allclose(up_axis(m), [0, 1, 0]), path


def test_leg_positions_block_by_block_are_the_forward_kinematics_of_the_whole_take(monkeypatch):
    import mocycle.contacts.legs as legs_module
    from mocycle.contacts.legs import chain_joints, chain_positions, chain_transforms, leg_joints

    walk = synthetic_walk(n_frames=250, fps=60, noise_deg=2.0, seed=3).motion
    chain = chain_joints(walk, leg_joints(find_feet(walk.skeleton)))
    Rw, W = chain_transforms(walk, chain)
    monkeypatch.setattr(legs_module, "POSITIONS_BLOCK", 64)  # four blocks, the last one short
    blocked = chain_positions(walk, chain)
    np.testing.assert_array_equal(blocked.data, W.data)
    full = walk.world_positions()
    np.testing.assert_allclose(blocked.data, full[:, chain], atol=1e-9)
    np.testing.assert_allclose(Rw.data, walk.world_transforms()[0][:, chain], atol=1e-12)


def test_the_floor_read_a_block_of_frames_at_a_time_is_the_lowest_foot_point(monkeypatch):
    import importlib

    from mocycle.contacts import floor_height, foot_points

    plant = importlib.import_module("mocycle.contacts.plant")
    walk = synthetic_walk(n_frames=300, fps=60, noise_deg=2.0, seed=4).motion
    up = up_axis(walk)
    lowest = float((walk.world_positions(end_sites=True)[:, foot_points(walk)] @ up).min())
    monkeypatch.setattr(plant, "FLOOR_BLOCK", 70)  # five blocks, the last one short
    assert floor_height(walk) == lowest
