"""Option fields shared by several tasks (one declaration, one default, one help line each)."""

from __future__ import annotations

from dataclasses import dataclass

from ..defaults import (
    AMC_FPS,
    CYCLE_METHODS,
    HARMONIC_MODELS,
    HARMONICS,
    MIN_PERIODS,
    ROOT_MODES,
    SWING_THRESHOLD,
)
from ..errors import OptionError
from .options import Choice, Flag, Integer, Options, Real, Text, option

__all__ = ["AMC_FPS", "CycleOptions", "MIN_PERIODS", "SWING_THRESHOLD", "amc_fps", "classes", "cycles", "delay",
           "feet", "foot_joints", "force_cycle", "harmonics", "joints", "method", "min_periods", "model", "pca",
           "phase_joints", "root", "take_cycles", "swing_joints", "take", "threshold", "which"]

METHODS = CYCLE_METHODS
MODELS = HARMONIC_MODELS
ROOTS = ROOT_MODES


def amc_fps():
    return option(AMC_FPS, "Frame rate of AMC input files, which do not store it (CMU: 120).",
                  Real(0, low_open=True))


def take():
    return option(None, "Which take of a glTF or FBX input to read: an animation's (FBX: animation stack's) name or "
                        "0-based index, as mocycle info lists them; default the first that moves the skeleton.", Text())


def takes():
    return option(None, "Which take of each glTF or FBX input to read: one name or 0-based index for every input, "
                        "or one per input separated by commas (e.g. Walking,Running), as mocycle info lists them; "
                        "default the first that moves the skeleton.", Text())


def take_for_each(take: str | None, n: int) -> list[str | None]:
    """The take to read from each of ``n`` inputs: ``take`` for every one, or, when it holds commas, its items
    one per input (an empty item: that input's default take)."""
    if take is None or "," not in take:
        return [take] * n
    items = [t.strip() for t in take.split(",")]
    if len(items) != n:
        raise OptionError("take", f"names {len(items)} takes for {n} inputs; give one take for every input, or "
                                  f"one per input separated by commas; got {take!r}")
    return [t or None for t in items]


def method(help: str = "How each take's cycle is extracted: harmonic (regression), centroid (paper 001) or cut."):
    return option("harmonic", help, Choice(METHODS))


def model(help: str = "Harmonic model: M1, M2 or M3 (see mocycle loop)."):
    return option("M1", help, Choice(MODELS))


def harmonics():
    return option("auto", f"Harmonics K: 'auto' ({HARMONICS}, capped by the frames) or a number.",
                  Integer(1, words={"auto": "auto"}))


def root(default: str, help: str):
    return option(default, help, Choice(ROOTS))


def cycles(default: int, help: str):
    return option(default, help, Integer(1))


def classes(help: str = "How many periodic motions to look for: 'auto' or N."):
    return option("auto", help, Integer(1, words={"auto": "auto"}))


# -- the phase options: what ``phase`` takes to find the periodic motion; loop, blend and transition take the same
def phase_joints():
    return joints("Joints to find the phase on: names, glob patterns or groups (legs, arms, spine), comma-separated; "
                  "default the whole body, then legs, then arms until one shows a periodic motion.")


def pca():
    return option("auto", "PCA dimensions before the cohomology: 'auto' (8), N or 'none'.",
                  Integer(1, words={"auto": "auto", "none": None, "0": None}, optional=True))


def delay():
    return option(2, "Delay embedding factor m (KTH thesis eq. 3.26; it used 2).", Integer(0))


def min_periods():
    return option(MIN_PERIODS, "Periods a periodic motion must cover (>= 1); below 1.5 the result is kept with a "
                               "warning.", Real(1.0))


def which(help: str = "Which part of each take to use: its number in the parts mocycle loop lists (0-based; "
                      "default: the steady part with the most cycles that loops).", words: tuple[str, ...] = ()):
    return option(None, help, Integer(0, words={w: w for w in words}, optional=True), flag="--part",
                  old_flags=("--class",))


def joints(help: str = "Joints to use: names, glob patterns or groups (legs, arms, spine), comma-separated."):
    return option(None, help, Text())


def threshold():
    return option(SWING_THRESHOLD, "Acceptable Swing Error, 0-2 (paper: 0.4; 0 accepts only perfectly geodesic "
                                   "swings).", Real(0, 2))


def force_cycle():
    return option(False, "Use a take's cycle even when it fails a loop check (a warning names the check).",
                  Flag())


def take_cycles(motions, labels, options) -> list:
    """Each take's cycle as ``blend`` and ``transition`` use it: the loop of one of its steady parts
    (:func:`~mocycle.cycle.parts.part_cycle`: ``options.which``, by default the part with the most cycles that
    loops), the same loop ``mocycle loop`` writes.  A take that does not loop raises with its label."""
    from ..cycle.parts import part_cycle

    return [part_cycle(m, which=options.which, method=options.method, model=options.model,
                       harmonics=options.harmonics, force=options.force, label=label, joints=options.joints,
                       classes=options.classes, pca=options.pca, delay=options.delay,
                       min_periods=options.min_periods) for m, label in zip(motions, labels, strict=True)]


def feet(help: str | None = None):
    from .feet_option import FEET_HELP, FEET_MODES

    return option("auto", help or FEET_HELP, Choice(FEET_MODES))


def foot_joints():
    from .feet_option import FOOT_JOINTS_HELP

    return option(None, FOOT_JOINTS_HELP, Text())


def swing_joints():
    return joints("Joints to segment: names, glob patterns or groups (legs, arms, spine), comma-separated "
                  "(default: the major bones, by name and motion energy).")


@dataclass(frozen=True)
class CycleOptions(Options):
    """How the cycle of each input take is found and checked: the options ``blend`` and ``transition`` share."""

    method: str = method()
    model: str = model()
    harmonics: int | str = harmonics()
    joints: str | None = phase_joints()
    classes: int | str = classes()
    which: int | None = which()
    pca: int | str | None = pca()
    delay: int = delay()
    min_periods: float = min_periods()
    amc_fps: float = amc_fps()
    take: str | None = take()
    force: bool = force_cycle()
    feet: str = feet()
    foot_joints: str | None = foot_joints()
