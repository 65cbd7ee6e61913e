"""Fuzzing the ASF and AMC readers: damaged text gives a MotionFileError naming the file and a real line,
or a skeleton and motion that write as BVH and read back; each example under a memory and time limit."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzing import edited_text, fuzz_settings, limits
from mocycle.datasets.asfamc_text import TINY_AMC, TINY_ASF
from mocycle.errors import MocycleWarning, MotionFileError
from mocycle.io.asfamc import parse_amc, parse_asf
from mocycle.io.bvh import format_bvh, parse_bvh

pytestmark = pytest.mark.filterwarnings("ignore::mocycle.errors.MocycleWarning")

ASF, AMC = TINY_ASF, TINY_AMC
VOCAB = [":version", ":name", ":units", ":root", ":bonedata", ":hierarchy", ":DEGREES", ":RADIANS", "begin", "end",
         "id", "name", "direction", "length", "axis", "dof", "limits", "order", "position", "orientation", "root",
         "lfemur", "ltibia", "thorax", "rx", "ry", "rz", "tx", "l", "XYZ", "ZYX", "XXY", "TX", "RZ", "(", ")", "deg",
         "rad", "angle", "1", "2", "3", "-1"]
FUZZ = fuzz_settings(150)
SKELETON = parse_asf(ASF, "fuzz.asf")


def _lines(text: str) -> int:
    return text.replace("\r\n", "\n").replace("\r", "\n").count("\n") + 1


def check_error(exc: MotionFileError, names: str, text: str) -> None:
    msg = str(exc)
    assert re.match(rf"fuzz\.({names})(:\d+)?: \S", msg), msg
    assert exc.line is None or 1 <= exc.line <= _lines(text), (exc.line, msg)


def check(asf_text: str, amc_text: str = AMC) -> None:
    """Both texts read (and the motion writes as BVH and reads back) or one MotionFileError names the file."""
    with limits(), warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", MocycleWarning)
        try:
            asf = parse_asf(asf_text, "fuzz.asf")
        except MotionFileError as exc:
            return check_error(exc, "asf", asf_text)
        try:
            motion = parse_amc(amc_text, asf, "fuzz.amc")
        except MotionFileError as exc:
            return check_error(exc, "asf|amc", amc_text)  # an AMC error, or the ASF's bones that cannot be built
        again = parse_bvh(format_bvh(motion), "again.bvh")
    assert again.n_frames == motion.n_frames and again.skeleton.names == motion.skeleton.names
    assert np.all(np.isfinite(again.rotations)) and np.all(np.isfinite(again.translations))


def test_seed_files_read():
    motion = parse_amc(AMC, SKELETON, "fuzz.amc")
    assert motion.n_frames == 3 and motion.n_joints == 4


@FUZZ
@given(edited_text(ASF, VOCAB))
def test_edited_asf(text):
    check(text)


@FUZZ
@given(edited_text(AMC, VOCAB))
def test_edited_amc(text):
    check(ASF, text)


@FUZZ
@given(st.text(max_size=400))
def test_random_text(text):
    check(text, text)


@FUZZ
@given(st.integers(0, len(ASF)), st.integers(0, len(AMC)))
def test_truncated(k, m):
    check(ASF[:k], AMC[:m])
