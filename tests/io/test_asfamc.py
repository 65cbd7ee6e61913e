"""Tests of the ASF/AMC reader: tiny hand-written files, bad input, and the CMU takes."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import shared_path
from mocycle.errors import MocycleWarning, MotionFileError
from mocycle.io.asfamc import AsfSkeleton, read_amc, read_asf, read_asfamc
from mocycle.motion import Motion

# --------------------------------------------------------------------------
# tiny hand-written files
# --------------------------------------------------------------------------
TINY_ASF = """\
# a one-bone skeleton
:version 1.10
:name tiny
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
  anything goes here
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name bone
     direction 1 0 0
     length 2
     axis 0 0 90  XYZ
    dof rx
    limits (-180.0 180.0)
  end
:hierarchy
  begin
    root bone
  end
"""

TINY_AMC = """\
#!OML:ASF tiny.asf
:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
bone 30
2
root 1 2 3 10 20 30
bone -45
"""


def write(tmp_path, name: str, text: str, newline: str = "\n"):
    """Write ``text`` to ``tmp_path/name`` with the given line ends; return the path."""
    p = tmp_path / name
    p.write_bytes(text.replace("\n", newline).encode())
    return p


@pytest.fixture
def tiny(tmp_path):
    return write(tmp_path, "tiny.asf", TINY_ASF), write(tmp_path, "tiny.amc", TINY_AMC)


def test_tiny_asf_fields(tiny):
    asf = read_asf(tiny[0])
    assert isinstance(asf, AsfSkeleton)
    assert asf.bones == ("bone",)
    assert asf.parents == ("root",)
    assert asf.dofs == (("rx",),)
    assert asf.axis_orders == ("XYZ",)
    np.testing.assert_array_equal(asf.axes, [[0, 0, 90]])
    np.testing.assert_array_equal(asf.directions, [[1, 0, 0]])
    np.testing.assert_array_equal(asf.lengths, [2])
    assert asf.limits == (((-180.0, 180.0),),)
    assert asf.units == {"mass": 1.0, "length": 0.45, "angle": "deg"}
    assert asf.root_order == ("TX", "TY", "TZ", "RX", "RY", "RZ")
    assert asf.name == "tiny"


def test_tiny_skeleton_layout(tiny):
    skel = read_asf(tiny[0]).to_skeleton()
    assert skel.names == ("root", "bone")
    assert skel.parents.tolist() == [-1, 0]
    np.testing.assert_array_equal(skel.offsets, np.zeros((2, 3)))  # length units not applied
    assert skel.channels[0] == ("Xposition", "Yposition", "Zposition",
                                "Zrotation", "Yrotation", "Xrotation")
    assert skel.channels[1] == ("Zrotation", "Yrotation", "Xrotation")
    assert len(skel.end_sites) == 1
    assert skel.end_sites[0].parent == 1
    np.testing.assert_allclose(skel.end_sites[0].offset, [2, 0, 0])


def test_single_bone_local_rotation_is_c_rx_cinv(tiny):
    m = read_asfamc(*tiny)
    assert m.n_frames == 2 and m.n_joints == 2
    C = Rotation.from_euler("xyz", [0, 0, 90], degrees=True)
    for t, angle in enumerate([30.0, -45.0]):
        want = C * Rotation.from_euler("x", angle, degrees=True) * C.inv()
        got = Rotation.from_quat(m.rotations[t, 1])
        assert (got * want.inv()).magnitude() < 1e-12
        # independently: C = Rz(90) carries x onto y, so C Rx(a) C^-1 = Ry(a)
        assert (got * Rotation.from_euler("y", angle, degrees=True).inv()).magnitude() < 1e-12


def test_tiny_root_and_forward_kinematics(tiny):
    m = read_asfamc(*tiny, fps=60)
    assert m.frame_time == pytest.approx(1 / 60)
    np.testing.assert_allclose(m.root_positions, [[1, 2, 3], [1, 2, 3]])
    root1 = Rotation.from_quat(m.rotations[1, 0])
    want = Rotation.from_euler("xyz", [10, 20, 30], degrees=True)  # = Rz Ry Rx
    assert (root1 * want.inv()).magnitude() < 1e-12
    # frame 1: root unrotated, the bone turns its end (2, 0, 0) by 30 degrees about y
    tip = m.world_positions(end_sites=True)[0, -1]
    a = np.radians(30)
    np.testing.assert_allclose(tip, [1 + 2 * np.cos(a), 2, 3 - 2 * np.sin(a)], atol=1e-12)


def test_read_amc_takes_skeleton_object_or_path(tiny):
    a = read_amc(tiny[1], read_asf(tiny[0]))
    b = read_amc(tiny[1], tiny[0])
    np.testing.assert_array_equal(a.rotations, b.rotations)
    assert a.frame_time == pytest.approx(1 / 120)


def test_radians(tmp_path, tiny):
    deg = read_asfamc(*tiny)
    asf_rad = TINY_ASF.replace("angle deg", "angle rad").replace(
        "axis 0 0 90", f"axis 0 0 {np.pi / 2}")
    amc_rad = (TINY_AMC.replace(":DEGREES", ":RADIANS")
               .replace("10 20 30", " ".join(str(float(np.radians(v))) for v in (10, 20, 30)))
               .replace("bone 30", f"bone {float(np.radians(30))}")
               .replace("bone -45", f"bone {float(np.radians(-45))}"))
    rad = read_asfamc(write(tmp_path, "rad.asf", asf_rad), write(tmp_path, "rad.amc", amc_rad))
    np.testing.assert_allclose(rad.rotations, deg.rotations, atol=1e-12)
    # without a header the AMC values follow the ASF's unit ...
    amc_plain = amc_rad.replace(":RADIANS\n", "")
    rad2 = read_amc(write(tmp_path, "plain.amc", amc_plain), tmp_path / "rad.asf")
    np.testing.assert_allclose(rad2.rotations, deg.rotations, atol=1e-12)
    # ... and an AMC header wins over the ASF's unit
    rad3 = read_amc(write(tmp_path, "hdr.amc", amc_rad), tiny[0])
    np.testing.assert_allclose(rad3.rotations, deg.rotations, atol=1e-12)


def test_axis_dof_and_root_orders_generalise(tmp_path):
    asf = (TINY_ASF.replace("axis 0 0 90  XYZ", "axis 10 20 30 ZXY")
           .replace("dof rx", "dof rz rx")
           .replace("limits (-180.0 180.0)", "limits (-180.0 180.0)\n  (-90 90)")
           .replace("order TX TY TZ RX RY RZ", "order RZ TX RX TY RY TZ")
           .replace("position 0 0 0", "position 0.5 0 -1")
           .replace("axis XYZ", "axis YXZ")
           .replace("orientation 0 0 0", "orientation 5 6 7"))
    amc = "1\nroot 40 1 50 2 60 3\nbone 15 25\n"
    m = read_asfamc(write(tmp_path, "o.asf", asf), write(tmp_path, "o.amc", amc))
    np.testing.assert_allclose(m.root_positions[0], [1.5, 2, 2])
    C_root = Rotation.from_euler("yxz", [5, 6, 7], degrees=True)
    M_root = Rotation.from_euler("zxy", [40, 50, 60], degrees=True)
    want = C_root * M_root * C_root.inv()
    assert (Rotation.from_quat(m.rotations[0, 0]) * want.inv()).magnitude() < 1e-12
    C = Rotation.from_euler("zxy", [10, 20, 30], degrees=True)
    M = Rotation.from_euler("zx", [15, 25], degrees=True)
    want = C * M * C.inv()
    assert (Rotation.from_quat(m.rotations[0, 1]) * want.inv()).magnitude() < 1e-12
    np.testing.assert_allclose(m.skeleton.offsets[0], [0.5, 0, -1])


def test_line_ends_tabs_blank_lines_and_missing_bones(tmp_path, tiny):
    ref = read_asfamc(*tiny)
    for nl in ("\r\n", "\r"):
        asf = write(tmp_path, "t.asf", TINY_ASF.replace("  ", "\t"), newline=nl)
        amc = write(tmp_path, "t.amc", TINY_AMC.replace("\n2\n", "\n\n\t\n2\n"), newline=nl)
        m = read_asfamc(asf, amc)
        np.testing.assert_allclose(m.rotations, ref.rotations, atol=1e-15)
    # a bone missing from a frame keeps zero dofs
    amc = write(tmp_path, "miss.amc", "1\nroot 0 0 0 0 0 0\n2\nroot 0 0 0 0 0 0\nbone 10\n")
    m = read_amc(amc, tiny[0])
    np.testing.assert_allclose(m.rotations[0, 1], [0, 0, 0, 1])


def test_truncated_last_frame_warns(tmp_path, tiny):
    amc = write(tmp_path, "cut.amc", TINY_AMC + "3\n")
    with pytest.warns(MocycleWarning, match="truncated"):
        m = read_amc(amc, tiny[0])
    assert m.n_frames == 3


def test_reading_tiny_files_gives_no_warning(tiny):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_asfamc(*tiny)


# --------------------------------------------------------------------------
# bad input: every problem is a MotionFileError naming the file and the line
# --------------------------------------------------------------------------
AMC_ERRORS = [
    # (description, AMC text, line, words the message must contain)
    ("unknown bone", "1\nroot 0 0 0 0 0 0\nfemur 3\n", 3, ["unknown bone", "femur"]),
    ("too few values", "1\nroot 0 0 0 0 0\n", 2, ["root", "5 values", "expected 6"]),
    ("too many values", "1\nroot 0 0 0 0 0 0\nbone 1 2\n", 3, ["bone", "expected 1"]),
    ("non-numeric value", "1\nroot 0 0 0 0 0 0\n2\nroot 0 0 x 0 0 0\n", 4, ["number", "'0 0 x"]),
    ("not finite", "1\nroot 0 0 0 0 0 0\nbone nan\n", 3, ["finite"]),
    ("truncated line", TINY_AMC[: TINY_AMC.index("20 30")], 8, ["root", "expected 6"]),
    ("frame gap", "1\nbone 1\n3\nbone 2\n", 3, ["frame number 3", "expected 2"]),
    ("bone before frame", ":DEGREES\nbone 1\n", 2, ["before the first frame"]),
    ("bone twice", "1\nbone 1\nbone 2\n", 3, ["twice"]),
    ("empty", "# nothing\n:DEGREES\n", 2, ["no frames"]),
    ("negative frame", "-1\nbone 1\n", 1, ["frame number"]),
]


@pytest.mark.parametrize("text,line,words", [e[1:] for e in AMC_ERRORS],
                         ids=[e[0] for e in AMC_ERRORS])
def test_amc_errors_name_file_and_line(tmp_path, tiny, text, line, words):
    amc = write(tmp_path, "bad.amc", text)
    with pytest.raises(MotionFileError) as info:
        read_amc(amc, tiny[0])
    msg = str(info.value)
    assert f"bad.amc:{line}:" in msg, msg
    assert info.value.line == line
    for word in words:
        assert word in msg, msg


ASF_ERRORS = [
    ("missing :bonedata", TINY_ASF[: TINY_ASF.index(":bonedata")], 14, [":bonedata"]),
    ("truncated in a bone", TINY_ASF[: TINY_ASF.index("  end")], 23, ["line 16", "'end'"]),
    ("truncated hierarchy", TINY_ASF[: TINY_ASF.rindex("  end")], 27, [":hierarchy", "'end'"]),
    ("missing :root", TINY_ASF.replace(":root", ":skin"), 28, [":root"]),
    ("not an asf", "HIERARCHY\nROOT Hips\n", 1, ["ASF keyword"]),
    ("bad direction", TINY_ASF.replace("direction 1 0 0", "direction 1 0"), 19, ["direction"]),
    ("text direction", TINY_ASF.replace("direction 1 0 0", "direction 1 a 0"), 19, ["'a'"]),
    ("bad axis order", TINY_ASF.replace("90  XYZ", "90 XYY"), 21, ["XYY"]),
    ("bad dof", TINY_ASF.replace("dof rx", "dof rq"), 22, ["rq"]),
    ("translation dof", TINY_ASF.replace("dof rx", "dof tx"), 22, ["not supported"]),
    ("unknown keyword", TINY_ASF.replace("id 1", "colour red"), 17, ["colour"]),
    ("no length", TINY_ASF.replace("length 2\n", ""), 16, ["'length'"]),
    ("bad unit", TINY_ASF.replace("angle deg", "angle grad"), 7, ["grad"]),
    ("bad root order", TINY_ASF.replace("TX TY TZ RX", "TX TX TZ RX"), 11, ["root order"]),
    ("unknown child", TINY_ASF.replace("root bone", "root bone arm"), 27, ["'arm'"]),
    ("unknown parent", TINY_ASF.replace("root bone", "arm bone"), 27, ["'arm'"]),
    ("bone not in hierarchy", TINY_ASF.replace("root bone", ""), 25, ["missing", "bone"]),
    ("bone called root", TINY_ASF.replace("name bone", "name Root"), 18, ["'root'"]),
]


@pytest.mark.parametrize("text,line,words", [e[1:] for e in ASF_ERRORS],
                         ids=[e[0] for e in ASF_ERRORS])
def test_asf_errors_name_file_and_line(tmp_path, text, line, words):
    asf = write(tmp_path, "bad.asf", text)
    with pytest.raises(MotionFileError) as info:
        read_asf(asf)
    msg = str(info.value)
    assert f"bad.asf:{line}:" in msg, msg
    assert info.value.line == line
    for word in words:
        assert word in msg, msg


def test_missing_file(tmp_path):
    with pytest.raises(MotionFileError, match="nope.asf"):
        read_asf(tmp_path / "nope.asf")


def test_every_prefix_and_random_garbage_gives_motionfileerror(tmp_path, tiny):
    """Cut or scribbled files either read or raise MotionFileError, nothing else."""
    asf = read_asf(tiny[0])
    rng = np.random.default_rng(7)
    samples = [("asf", TINY_ASF[:k]) for k in range(0, len(TINY_ASF), 3)]
    samples += [("amc", TINY_AMC[:k]) for k in range(len(TINY_AMC))]
    alphabet = np.array(list("ab9.-: \n\t#()e"))
    for kind, base in (("asf", TINY_ASF), ("amc", TINY_AMC)):
        for _ in range(150):
            chars = np.array(list(base))
            where = rng.integers(0, len(chars), size=rng.integers(1, 4))
            chars[where] = rng.choice(alphabet, size=len(where))
            samples.append((kind, "".join(chars)))
    samples.append(("amc", "\x00\xff\ufffd garbage \x01\n"))
    for kind, text in samples:
        p = tmp_path / f"x.{kind}"
        p.write_bytes(text.encode("utf-8", "surrogatepass"))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", MocycleWarning)
                read_asf(p) if kind == "asf" else read_amc(p, asf)
        except MotionFileError as exc:
            assert "x." + kind in str(exc)


# --------------------------------------------------------------------------
# the CMU takes
# --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cmu_01():
    asf = read_asf(shared_path("cmu", "01.asf"))
    return asf, read_amc(shared_path("cmu", "01_01.amc"), asf)


@pytest.mark.shared_data
def test_cmu_01_skeleton_units_kept(cmu_01):
    asf, m = cmu_01
    assert asf.units["length"] == pytest.approx(0.45)
    assert asf.angle_unit == "deg"
    assert m.n_joints == 31 and m.n_frames == 2751
    j = m.skeleton.index("ltibia")  # its offset is the (unscaled) lfemur vector
    np.testing.assert_allclose(m.skeleton.offsets[j], 7.1578 * np.array([0.34202, -0.939693, 0]))


@pytest.mark.shared_data
def test_cmu_01_matches_bvh_conversion(cmu_01):
    """01_01.amc against the CMU BVH conversion of the same take (frames 1.. of the BVH).

    The BVH was written with 4-5 decimals, so agreement is to ~1e-4 file units.
    One known difference in the rest skeleton: the BVH attaches the children of a
    branching bone (thorax -> lowerneck, lclavicle, rclavicle; lwrist -> lhand,
    lthumb; rwrist -> rhand, rthumb) at the branching bone's *start* (offset 0),
    where the ASF puts them at its end.  So the full-body FK check runs our
    rotations and root track on the BVH's rest offsets; the legs are checked on
    our own skeleton.
    """
    from mocycle.io.bvh import read_bvh

    asf, m = cmu_01
    bvh = read_bvh(shared_path("cmu", "01_01.bvh"))
    assert bvh.n_frames == m.n_frames + 1  # frame 0 of the BVH is an added pose
    bvh = bvh[1:]
    ours, theirs = m.skeleton, bvh.skeleton
    assert theirs.n_joints == ours.n_joints
    assert theirs.parents.tolist() == ours.parents.tolist()
    assert [e.parent for e in theirs.end_sites] == [e.parent for e in ours.end_sites]
    np.testing.assert_allclose([e.offset for e in theirs.end_sites],
                               [e.offset for e in ours.end_sites], atol=1e-4)

    branch_children = {j for j in range(1, ours.n_joints)
                       if len(ours.children(int(ours.parents[j]))) > 1 and ours.parents[j] != 0}
    assert {ours.names[j] for j in branch_children} == {
        "lowerneck", "lclavicle", "rclavicle", "lhand", "lthumb", "rhand", "rthumb"}
    same = [j for j in range(ours.n_joints) if j not in branch_children]
    np.testing.assert_allclose(theirs.offsets[same], ours.offsets[same], atol=1e-4)
    np.testing.assert_array_equal(theirs.offsets[sorted(branch_children)], 0.0)

    # root track: the BVH has 4 decimals
    assert np.abs(bvh.root_positions - m.root_positions).max() < 6e-5
    # world rotations do not depend on offsets: equal for every joint and frame
    world_theirs, _ = bvh.world_transforms()
    world_ours, _ = m.world_transforms()
    assert np.abs(world_theirs - world_ours).max() < 1e-5  # measured 5.1e-6
    # full-body FK with our rotations on the BVH's rest offsets (measured 7.8e-5)
    on_bvh_rest = Motion(theirs, m.rotations, None, m.frame_time, root_positions=m.root_positions)
    err = np.abs(bvh.world_positions(end_sites=True) - on_bvh_rest.world_positions(end_sites=True))
    assert err.max() < 1e-4
    # legs (root, hips, femurs ... toes) on our own skeleton (measured 8.7e-5)
    legs = [j for j in range(ours.n_joints)
            if ours.names[j] in {"root", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes",
                                 "rhipjoint", "rfemur", "rtibia", "rfoot", "rtoes"}]
    assert len(legs) == 11
    err = np.abs(bvh.world_positions()[:, legs] - m.world_positions()[:, legs])
    assert err.max() < 1e-4


@pytest.mark.shared_data
def test_cmu_11_structure():
    m = read_asfamc(shared_path("cmu", "11.asf"), shared_path("cmu", "11_01.amc"))
    assert m.n_frames == 597
    assert m.n_joints == 31
    assert m.skeleton.names[0] == "root"
    assert np.all(np.isfinite(m.rotations)) and np.all(np.isfinite(m.translations))
    assert np.all(np.isfinite(m.world_positions(end_sites=True)))
    np.testing.assert_allclose(np.linalg.norm(m.rotations, axis=-1), 1.0)


def test_deep_bone_chain_reads_and_writes(tmp_path):
    """An ASF chain deeper than Python's recursion limit reads, converts and writes as BVH."""
    import sys

    from mocycle.io import read, write

    n = sys.getrecursionlimit() + 500
    asf = [":units", "  angle deg", ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ", "   position 0 0 0",
           "   orientation 0 0 0", ":bonedata"]
    for i in range(n):
        asf += ["  begin", f"     name b{i}", "     direction 0 1 0", "     length 1", "     dof rx", "  end"]
    asf += [":hierarchy", "  begin", "    root b0", *(f"    b{i} b{i + 1}" for i in range(n - 1)), "  end"]
    (tmp_path / "chain.asf").write_text("\n".join(asf) + "\n")
    amc = ["1", "root 0 0 0 0 0 0", *(f"b{i} 1" for i in range(n))]
    (tmp_path / "chain_01.amc").write_text("\n".join(amc) + "\n")
    m = read(tmp_path / "chain_01.amc")
    assert m.n_joints == n + 1 and m.skeleton.parents[-1] == n - 1
    back = read(write(m, tmp_path / "chain.bvh"))
    assert back.n_joints == n + 1
    assert np.abs(back.world_positions()[0, -1] - m.world_positions()[0, -1]).max() < 1e-6
