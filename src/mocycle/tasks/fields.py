"""Option fields shared by several tasks (one declaration, one default, one help line each)."""

from __future__ import annotations

from ..io.asfamc import AMC_FPS
from ..swings.segment import DEFAULT_THRESHOLD as SWING_THRESHOLD
from .options import Choice, Flag, Integer, Real, Text, option

__all__ = ["AMC_FPS", "SWING_THRESHOLD", "amc_fps", "classes", "cycles", "harmonics", "joints", "method", "model",
           "root", "swing_joints", "threshold"]

METHODS = ("harmonic", "centroid", "cut")
MODELS = ("M1", "M2", "M3")
ROOTS = ("inplace", "motion")


def amc_fps():
    return option(AMC_FPS, "Frame rate of AMC input files, which do not store it (CMU: 120).",
                  Real(0, low_open=True))


def method(help: str = "How each take's cycle is extracted: harmonic (regression), centroid (paper 001) or cut."):
    return option("harmonic", help, Choice(METHODS))


def model(help: str = "Harmonic model: M1, M2 or M3 (see mocycle loop)."):
    return option("M1", help, Choice(MODELS))


def harmonics():
    return option("auto", "Harmonics K: 'auto' (20, capped by the frames) or a number.",
                  Integer(1, words={"auto": "auto"}))


def root(default: str, help: str):
    return option(default, help, Choice(ROOTS))


def cycles(default: int, help: str):
    return option(default, help, Integer(1))


def classes(help: str = "Number of periodic motions: 'auto' or N."):
    return option("auto", help, Integer(1, words={"auto": "auto"}))


def joints(help: str = "Joints to use: names, glob patterns or groups (legs, arms, spine), comma-separated."):
    return option(None, help, Text())


def threshold():
    return option(SWING_THRESHOLD, "Acceptable Swing Error, 0-2 (paper: 0.4; 0 accepts only perfectly geodesic "
                                   "swings).", Real(0, 2))


def force_cycle():
    return option(False, "Use a take's cycle even when it fails a loop check (a warning names the check).",
                  Flag())


def swing_joints():
    return joints("Joints to segment: names, glob patterns or groups (legs, arms, spine), comma-separated "
                  "(default: the major bones, by name and motion energy).")
