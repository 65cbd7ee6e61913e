"""Steady activities of a take: where it walks straight, turns, runs, waves or stands, before anything is looped.

A take that changes what it does (walk, turn, walk; walk then wave; a whole capture session) has no one
cycle: a loop fitted over all of it averages the parts into a motion the actor never made.
:func:`segment_activities` cuts the take into parts that each do one thing, from evidence that does not
depend on the phase; every loop is then made from one part's frames only (:mod:`mocycle.cycle.parts`).

1. **Foot landings** (:func:`find_landings`): where a lifted foot comes down.  Landings that alternate between
   the feet, each step between :data:`MIN_STEP_S` and :data:`MAX_STEP_S` seconds, are *gait*; the frames
   between a foot's landing and its next landing are one **stride**, the gait's full cycle (two steps)
   measured without any phase.
2. **Each stride's figures**: its period (frames), its speed (the travel joint's horizontal distance over its
   time), its flight and its double support (the shares of its frames with no foot and with both feet on the
   floor).  A step is a *run* when its strides have a flight phase, a *walk* when they have double support,
   and only where the feet show neither does the speed decide (:func:`gait_of`).
3. **Steps of one gait and tempo** make a part: consecutive steps of the same gait whose stride periods stay
   within :data:`TEMPO_CHANGE` of the part's median so far.  A part reaches up to a step beyond its first
   and last landing (the take starts or ends mid-stride) while its legs still repeat the stride.
4. **Turns** (:func:`_turn_runs`): within a gait part, the hips' turning rate over one stride about each frame
   (their sway within a stride cancels) cuts it into straight parts, turning parts that hold the turn's core
   (at least :data:`TURN_CORE_SHARE` of its fastest rate, grown to :data:`TURN_LEAST` strides when the turn
   lasts that long) and the turn's slower start and end as transitions.
5. **The frames between gait parts** (the legs stand, or move without alternating landings) are looked at
   for a repeating motion (:func:`_periodic_in`): the moving arm joints first where the legs stand (a wave),
   the whole body first where they move (a dance step), region by region, so that several such motions are
   parts of their own; what holds no repeating motion is a **gesture** (the body moves) or **standing**
   (it barely does), never looped.  A rig whose feet are not found by name is looked at the same way.

A part is worth a loop when it holds at least ``min_periods`` cycles of its own phase, and a part without
gait at least :data:`MIN_REPEATS` (it must be seen to repeat).  Gait parts carry their **stride phase**
(:func:`stride_phase`): time in cycles through a line fitted to the landings, the period estimator that still
works on a part of 1.2 cycles where the circular coordinate winds about once.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field, replace

import numpy as np

from . import _validate
from .axes import vertical_axis
from .contacts import body_height, find_feet, up_axis
from .contacts.detect import heights_and_speeds, local_floor
from .contacts.legs import chain_joints, chain_positions
from .contacts.smooth import minimum
from .defaults import MIN_PERIODS
from .errors import MocycleError, NoPeriodicMotion
from .features import HeadingFrame, pose_matrix
from .motion import Motion
from .phase.analysis import PERIOD_AGREEMENT, PeriodicMotion, PhaseResult, find_phase_every
from .phase.period import autocorrelation_period, moving_average, repetition_distance
from .rotations import mean_rotations, quat_angles

#: A step (landing to the other foot's landing) lasts at least / at most this long, seconds.
MIN_STEP_S, MAX_STEP_S = 0.15, 1.2
#: A step next to a turning one turns too when its strides turn the same way by more than this many degrees.
TURN_EDGE_DEG = 7.0
#: Two consecutive steps of a gait differ in length by at most this factor (a limp stays under it).
STEP_RATIO = 1.6
#: The legs of a gait part are like themselves one stride later: unlikeness (repetition distance) under this.
UNLIKE = 0.5
#: ... and a take of one step (two landings) must be more alike still, its evidence being the shorter.
UNLIKE_ONE_STEP = 0.2
#: The hips turning by more than this many degrees per stride (over one stride about a frame) are turning.
TURN_DEG = 15.0
#: A turn's core, the frames a turning part holds, turns at least this share of the turn's fastest rate; the
#: frames of the turn slower than that (its start and end) are a transition of their own when they last a
#: quarter of a stride or more, part of the straight walk beside them when less.
TURN_CORE_SHARE = 0.5
#: A step whose stride period differs by more than this share from the median of its part so far starts
#: another part (a tempo that drifts step by step is caught as surely as one that jumps).
TEMPO_CHANGE = 0.2
#: A stride whose feet are both off the floor for at least this share of its frames has a flight phase: a run.
FLIGHT_SHARE = 0.05
#: A stride with both feet on the floor for at least this share of its frames (and no flight) is a walk: walking
#: keeps a foot down at every instant and both at each hand-over (double support; 20-55 % of a stride on the
#: shared walks as the landings' heights see it, 0-8 % on their runs).
DOUBLE_SUPPORT_SHARE = 0.12
#: Feet that show both, a flight phase and double support each on at least this share of a stride, cannot tell:
#: a run lands one foot after the other leaves (no double support at all on the shared runs with flight), a walk
#: keeps a foot down (no flight); both at once are contacts a rig's floating feet make unsure (CMU takes on the
#: iClone rig: 6-37 % "flight" and 4-12 % double support while walking).
MIXED_SHARE = 0.03
#: Where the feet cannot tell (neither flight nor double support, or both), faster than this many body heights per
#: second is a run (people switch from walking to running at about 2 m/s, 1.1-1.2 body heights per second).
RUN_SPEED = 1.25
#: A motion repeating more slowly than once in this many seconds is a sequence done again (a take played twice in
#: a session), not one cyclic motion: no part of its own (strides last at most 2 × MAX_STEP_S; waves, dance steps,
#: punches and sword swings repeat in 0.3-3 s).
MAX_REPEAT_S = 8.0
#: Frames without gait shorter than this many seconds are transitions, not looked at for another motion.
MIN_OTHER_S = 1.0
#: A joint of an arm moves when its rotation's spread is at least this share of the most moving arm joint's.
MOVING_SHARE = 0.25
#: The body stands when its joints' mean rotation spread is under this many degrees.
STILL_DEG = 4.0
#: A motion without gait (arms, the whole body) must be seen to repeat: at least this many periods, so that it is
#: compared with itself a whole period later (a raised and lowered hand winds once, a wave many times).
MIN_REPEATS = 2.0
#: Two stretches of frames a lag apart are compared only where they overlap by at least this many frames and
#: one frame per ``LAG_PER_OVERLAP`` frames of the lag (fewer frames say nothing of a repeat).
MIN_OVERLAP_FRAMES, LAG_PER_OVERLAP = 4, 6.0
#: The legs' own period is sought within these shares of the landings' (a stride's period, not a step's or two
#: strides').
PERIOD_SEARCH = (0.75, 1.33)
#: A one-cycle clip's wrap is looked for between these shares of its length (a cycle that repeats within the
#: clip is more than one cycle), and its ends are the mean step of its first two and last two frames.
ONE_CYCLE_LAGS = (0.3, 0.8)
#: Feet that land a period apart, each foot's landings within this share of a period found without gait, step in
#: time with it (a landing is found within a frame or two: a tenth of a stride at 30 fps).
IN_STEP = 0.1
#: A motion without gait repeats no faster than this many seconds a period (faster is tremor or noise).
MIN_REPEAT_S = 0.25
#: ... its frames repeat where they are like themselves a period later (repetition distance under this)
ALIKE = 0.5
#: ... at the shortest period their own frames repeat at: a region found at a period is looked at again at its
#: own (shorter) period at most this many times (a motion repeats at twice its period too)
PERIOD_REFINES = 2
#: ... and move: at least this share of the largest local speed of those frames (not a gesture's stillness).
BUSY_SHARE = 0.2
#: Frames a second the cohomology looks at in frames without gait unless told otherwise (``step``): a take of
#: more is looked at on every ``round(fps / PHASE_RATE)``-th frame (4 at 120 fps), so its points on the circle lie as
#: far apart and its delay spans as long as in a 30 fps take.  A body's cycle holds no motion a 30 fps capture
#: misses; 120 points a second only cost the cohomology (the Rips filtration grows with the cube of its landmarks).
#: Frames where the feet land are looked at on every frame all the same (a stretch between gait parts, a gait
#: part whose phase is asked of ``joints``): such a stretch is a gait looked at for as few as ``min_periods``
#: cycles, whose period must match its strides within a few percent, and a cycle and a fifth at 30 points a second
#: hold too few points for that (a two-stride run came out 7 % short at 120 fps).
PHASE_RATE = 30.0


def _least_overlap(lag):
    """The fewest frames (a number or an array, as ``lag``) two stretches ``lag`` frames apart must share."""
    return np.maximum(MIN_OVERLAP_FRAMES, lag / LAG_PER_OVERLAP)


@dataclass(kw_only=True)
class Activity:
    """One part of a take: frames ``[start, stop)``, what it does, and whether it is worth a loop.

    ``kind``: ``"walk straight"``, ``"walk turning left"``, ``"run turning right"``, ``"arms"`` (a limb
    repeats while the legs stand), ``"periodic"`` (the whole body repeats without walking), ``"transition"``,
    ``"gesture"`` or ``"standing"``; ``limbs``: the joints a phase is found on (``"legs"``, ``"arms"``, joint
    names joined by commas, ``"all"``); ``period_frames``: the stride period (gait) or NaN until a phase is
    found; ``speed``: units per second of the travel joint, horizontal; ``turn_deg``: the hips' heading change
    over the part (positive: left, about the vertical); ``landings``: per foot side, the landing frames in the
    part (take frames); ``loop``: worth a loop; ``reason``: in plain words, why not (or what it is).
    """

    start: int
    stop: int
    kind: str
    limbs: str = "all"
    period_frames: float = float("nan")
    speed: float = float("nan")
    turn_deg: float = 0.0
    loop: bool = False
    reason: str = ""
    landings: dict[str, list[int]] = field(default_factory=dict)
    #: whether the legs stand over the part (known for the parts without gait)
    legs_still: bool = True
    #: the phase of the part's frames (frame ``start`` first), a PeriodicMotion, once known
    periodic: PeriodicMotion | None = field(default=None, repr=False)
    #: the whole take is one cycle (a game clip): its frames are the loop (:func:`one_cycle`)
    one_cycle: bool = False
    #: a part without gait whose feet land in step with its period (each foot's landings a period apart,
    #: :func:`_in_step`): the landings see it repeat, so it needs the gait's cycles, not :data:`MIN_REPEATS`
    in_step: bool = False

    @property
    def n_frames(self) -> int:
        return self.stop - self.start

    @property
    def gait(self) -> bool:
        return self.kind.startswith(("walk", "run"))

    @property
    def n_periods(self) -> float:
        p = self.period_frames
        return self.n_frames / p if np.isfinite(p) and p > 0 else float("nan")

    @property
    def turn_per_cycle_deg(self) -> float:
        n = self.n_periods
        return self.turn_deg / n if np.isfinite(n) and n > 0 else float("nan")

    @property
    def slug(self) -> str:
        """The kind as a file-name part: ``walk-turning-left``."""
        return self.kind.replace(" ", "-")

    def to_dict(self) -> dict:
        def num(v):
            return float(v) if np.isfinite(v) else None

        return {"frames": [int(self.start), int(self.stop)], "kind": self.kind, "limbs": self.limbs,
                "period_frames": num(self.period_frames), "n_periods": num(self.n_periods),
                "speed": num(self.speed), "turn_deg": float(self.turn_deg),
                "turn_per_cycle_deg": num(self.turn_per_cycle_deg), "loop": self.loop, "reason": self.reason,
                "landings": {k: [int(f) for f in v] for k, v in self.landings.items()}}


@dataclass(kw_only=True)
class Activities:
    """The parts of a take, in frame order, tiling part of ``[0, n_frames)``; ``feet``: whether the rig's feet
    were found (without them every take is one part); ``reason``: how the take was cut, in plain words."""

    parts: list[Activity]
    n_frames: int
    frame_time: float
    feet: bool
    reason: str
    #: the foot landings the parts were cut by (found once: the loop checks read them again), or None
    landings: Landings | None = field(default=None, repr=False)

    def loopable(self) -> list[Activity]:
        return [p for p in self.parts if p.loop]

    def to_dict(self) -> dict:
        return {"parts": [p.to_dict() for p in self.parts], "frames": self.n_frames, "fps": 1.0 / self.frame_time,
                "feet_found": self.feet, "reason": self.reason}


# --------------------------------------------------------------------------------------------- landings
@dataclass(frozen=True)
class Landings:
    """Foot landings of a take in frame order: ``frames`` ``(n,)``, ``foot`` ``(n,)`` (index into ``sides``),
    ``sides`` (the feet's sides), and each frame's count of feet on the floor ``down`` ``(T,)``."""

    frames: np.ndarray
    foot: np.ndarray
    sides: tuple[str, ...]
    down: np.ndarray
    #: ``(n,)`` whether each landing was measured from its stance's own level (:func:`find_landings`), or None
    own: np.ndarray | None = None


#: A foot is lifted above this height over its floor (body heights), and has landed below LAND_HEIGHT.
LIFT_HEIGHT, LAND_HEIGHT = 0.04, 0.02
#: Where the landings make no gait, a stance's own level: a contact joint's lowest over STANCE_FLOOR_S seconds
#: about a frame (a stance beside every swing of a stride), when under STANCE_CAP (body heights) above its
#: floor (higher, the foot is held up); frames within STANCE_MARGIN_S of a chain of landings keep theirs, unless
#: the own levels make a chain OWN_CHAIN_MORE landings longer there.
STANCE_FLOOR_S, STANCE_CAP, STANCE_MARGIN_S = 0.6, 0.06, 0.5
#: Where the stances' own levels make a chain of landings this many longer (a stride) than every chain of the
#: floor's it meets, the landings there are measured from the stances' own levels (one more is often only a
#: foot that comes down at another floor where one take meets the next).
OWN_CHAIN_MORE = 2


def find_landings(motion: Motion) -> Landings | None:
    """The landings of ``motion``'s feet (``None`` when the rig's feet are not found by name).

    A landing is where a foot that was lifted (its lower contact joint, ankle or toe, more than
    :data:`LIFT_HEIGHT` of the body height above its floor) comes down (under :data:`LAND_HEIGHT`).  Heights
    only, no speeds: a foot that glides on the floor (a retargeted or synthetic take, a fitted loop) still
    lands where it comes down, and feet that stay down while the legs sway make no landing.  The floor of
    each joint is its lowest level nearby (:func:`~mocycle.contacts.detect.local_floor`).  Where those
    landings make no gait (frames more than :data:`STANCE_MARGIN_S` from every chain of three), and where the
    stances measured from their own level (:func:`_stance_floor`) make a chain a stride longer than every chain
    of the floor's they meet, the stances are measured from their own level instead: a take joined to others at
    another floor height, a floor that rises, or one that drifts from stance to stance (a retargeted rig's
    ankles) puts them a few percent above the floor of the frames about them and breaks the floor's chain;
    such landings are marked (``own``) and no chain passes between them and the others
    (:func:`_landings_from`)."""
    try:
        feet = find_feet(motion.skeleton)
    except MocycleError:
        return None
    up = up_axis(motion)
    joints = [j for f in feet for j in f.contact_joints]
    W = chain_positions(motion, chain_joints(motion, joints))
    body = body_height(motion, up)
    h, _, _ = heights_and_speeds(motion, joints, up, positions=W)
    h = h / body
    h = h - local_floor(h, motion.fps)
    return _landings_from(h, [len(f.contact_joints) for f in feet], tuple(f.side for f in feet), motion.fps)


def _landings_from(h: np.ndarray, sizes: list[int], sides: tuple[str, ...], fps: float) -> Landings:
    """:func:`find_landings` from the heights ``h`` ``(T, C)`` of the feet's contact joints above their floor (body
    heights; ``sizes``: contact joints per foot, in order): the landings over the floor, and, where they make
    no chain (frames more than :data:`STANCE_MARGIN_S` from every chain of three) or where the stances' own
    levels make a chain :data:`OWN_CHAIN_MORE` landings longer than every chain of the floor's it meets (a floor
    that drifts from stance to stance breaks the floor's chain in pieces), those over the stances' own levels
    (:func:`_stance_floor`)."""
    found = _landings_of(h, sizes, sides)
    T = h.shape[0]
    margin = int(round(STANCE_MARGIN_S * fps))
    free = np.ones(T, dtype=bool)  # frames more than the margin from every chain's frames
    chains = _gait_chains(found, fps, least=3)
    for chain in chains:
        free[max(0, found.frames[chain[0]] - margin):found.frames[chain[-1]] + margin + 1] = False
    spans = np.array([(found.frames[c[0]], found.frames[c[-1]], c.size) for c in chains]).reshape(-1, 3)
    own = _landings_of(h - _stance_floor(h, fps), sizes, sides)
    for chain in _gait_chains(own, fps, least=3):  # the stances' own levels make a chain a stride longer
        a, b = int(own.frames[chain[0]]), int(own.frames[chain[-1]])  # than every chain of the floor's it meets
        meets = (spans[:, 0] <= b) & (spans[:, 1] >= a)
        if chain.size >= spans[meets, 2].max(initial=0) + OWN_CHAIN_MORE:
            free[a:b + 1] = True
    if not free.any():
        return found
    keep_old = ~free[found.frames]
    keep_new = free[own.frames]
    frames = np.concatenate([found.frames[keep_old], own.frames[keep_new]])
    foot = np.concatenate([found.foot[keep_old], own.foot[keep_new]])
    mark = np.concatenate([np.zeros(int(keep_old.sum()), bool), np.ones(int(keep_new.sum()), bool)])
    order = np.argsort(frames, kind="stable")
    down = np.where(free, own.down, found.down)
    return Landings(frames[order], foot[order], sides, down, mark[order])


def _landings_of(h: np.ndarray, sizes: list[int], sides: tuple[str, ...]) -> Landings:
    """The landings of feet whose contact joints (``sizes`` per foot, in order) stand ``h`` ``(T, C)`` above
    their floor (body heights)."""
    frames, foot = [], []
    down = np.zeros(h.shape[0], dtype=np.int8)
    col = 0
    for f, n in enumerate(sizes):
        low = h[:, col:col + n].min(axis=1)
        col += n
        landed = low < LAND_HEIGHT
        down += landed
        # a frame under LAND_HEIGHT is a landing when the foot was lifted (above LIFT_HEIGHT) since the last such
        # frame: the count of lifted frames grew since then
        low_frames = np.flatnonzero(landed)
        lifts = np.cumsum(low > LIFT_HEIGHT)[low_frames]
        new = np.diff(lifts, prepend=0) > 0
        frames.extend(low_frames[new].tolist())
        foot.extend([f] * int(new.sum()))
    order = np.argsort(frames, kind="stable")
    return Landings(np.asarray(frames, dtype=np.intp)[order], np.asarray(foot, dtype=np.intp)[order], sides, down)


def _stance_floor(h: np.ndarray, fps: float) -> np.ndarray:
    """``(T, C)``: each contact joint's own level about a frame (its lowest over :data:`STANCE_FLOOR_S`) where
    that is under :data:`STANCE_CAP` above the floor of heights ``h`` ``(T, C)``, else 0 (a foot held up); the
    floor itself within half that time of the first and last frames (a window the take cuts short may hold no
    stance)."""
    size = max(1, int(round(STANCE_FLOOR_S * fps)))
    pad = np.zeros((size,) + h.shape[1:])
    near = minimum(np.concatenate([pad, h, pad]), size)[size:size + h.shape[0]]
    return np.where(near < STANCE_CAP, near, 0.0)


def _gait_chains(landings: Landings, fps: float, least: int = 3) -> list[np.ndarray]:
    """Runs of landing indices that alternate feet with steps of plausible length (at least ``least``
    landings; 3: one whole stride)."""
    lo, hi = MIN_STEP_S * fps, MAX_STEP_S * fps
    chains, run = [], [0] if landings.frames.size else []
    for i in range(1, landings.frames.size):
        step = landings.frames[i] - landings.frames[i - 1]
        before = landings.frames[i - 1] - landings.frames[run[-2]] if len(run) >= 2 else step
        same_floor = landings.own is None or landings.own[i] == landings.own[i - 1]  # (another take's floor)
        if landings.foot[i] != landings.foot[i - 1] and lo <= step <= hi and same_floor and \
                1 / STEP_RATIO <= step / before <= STEP_RATIO:
            run.append(i)
        else:
            chains.append(run)
            run = [i]
    if run:
        chains.append(run)
    return [np.asarray(c, dtype=np.intp) for c in chains if len(c) >= least]


def stride_periods(landings: Landings, fps: float, start: int = 0, stop: int | None = None) -> list[int]:
    """The strides (frames from a foot's landing to its next, the other foot landing once between, each step
    of plausible length) whose landings lie in frames ``start .. stop``."""
    out: list[int] = []
    for chain in _gait_chains(landings, fps):
        f = landings.frames[chain]
        f = f[(f >= start) & (f <= (stop if stop is not None else f.max()))]
        out.extend(int(f[k + 2] - f[k]) for k in range(f.size - 2))
    return out


# ------------------------------------------------------------------------------------------- segmentation
def heading_degrees(motion: Motion) -> np.ndarray:
    """The hips' (travel joint's) heading ``(T,)`` in degrees, unwrapped, positive turning left about up: made
    once per motion and kept with it (read-only), as the segmentation and every part's checks read it."""
    return motion.cache("heading degrees", _heading_degrees)


def _heading_degrees(motion: Motion) -> np.ndarray:
    frame = HeadingFrame.fit(motion)
    _, psi = frame.tilt(motion)
    # heading_angles runs from e1 towards e2 = up x e1: counter-clockwise seen from above, i.e. to the left
    out = np.degrees(np.asarray(psi, dtype=np.float64))
    out.setflags(write=False)
    return out


def _body_height(motion: Motion) -> float:

    return float(body_height(motion, up_axis(motion)))


def _horizontal_path(motion: Motion) -> np.ndarray:
    """The travel joint's world position ``(T, 3)`` with its vertical component removed."""

    up = vertical_axis(motion)
    p = motion.joint_path(motion.travel_joint)
    return p - np.outer(p @ up, up)


def _stride_figures(chain, landings, heading, path, fps):
    """Per stride of a chain (landing k to landing k+2, the same foot) ``(n, 5)``: period (frames), turn (deg),
    speed (units/s), flight and double support (the shares of its frames with no foot and with both feet on
    the floor, :attr:`Landings.down`)."""
    f = landings.frames[chain]
    out = []
    for k in range(f.size - 2):
        a, b = int(f[k]), int(f[k + 2])
        speed = float(np.linalg.norm(path[b] - path[a])) * fps / (b - a)
        down = landings.down[a:b]
        out.append((float(b - a), float(heading[b] - heading[a]), speed, float(np.mean(down == 0)),
                    float(np.mean(down >= 2))))
    return np.asarray(out)


def gait_of(flight: float, double: float, speed: float, body: float) -> str:
    """``"walk"`` or ``"run"``, told by the feet: a flight phase (:data:`FLIGHT_SHARE`) without double support is
    a run, double support (:data:`DOUBLE_SUPPORT_SHARE`) without flight a walk (neither on more than
    :data:`MIXED_SHARE` of the stride); where the feet show neither or both (contacts a rig's floating feet make
    unsure) the speed decides (:data:`RUN_SPEED` body heights per second)."""
    flies = flight >= FLIGHT_SHARE and double < MIXED_SHARE
    both = double >= DOUBLE_SUPPORT_SHARE and flight < MIXED_SHARE
    if flies != both:
        return "run" if flies else "walk"
    return "run" if speed > RUN_SPEED * body else "walk"


def _step_gaits(strides: np.ndarray, body: float) -> list[tuple[str, float]]:
    """Each step's gait (:func:`gait_of`) and stride period: step i lies in strides i-1 and i (those that
    exist).  Which way a step turns is decided later, frame by frame (:func:`_turn_runs`)."""
    out = []
    for i in range(strides.shape[0] + 1):
        rows = strides[max(0, i - 1): i + 1]
        out.append((gait_of(rows[:, 3].mean(), rows[:, 4].mean(), rows[:, 2].mean(), body), float(rows[:, 0].mean())))
    return out


#: How much the strides of a straight gait may change, over three strides before a landing against three after,
#: and still be one gait: in period and speed (shares), in flight and double support (shares of a stride) and in
#: posture (the stride's mean pose, :func:`_stride_poses`, as a share of the pose's swing within a stride: how bent
#: the knees are and where the arms are carried, what tells one take of a walk from the next at the same tempo and
#: speed), each as the scale of its change.  Where the root of the sum of the squared scaled changes passes
#: GAIT_CHANGE and is STEADY_SIDES times the spread within either side (a step between two steady gaits, as
#: where one take meets the next, not the ramp of a walk that starts from standing), the gait changes there.
STRIDE_STEPS = {"period": 0.08, "speed": 0.15, "flight": 0.12, "double support": 0.15, "pose": 0.5}
GAIT_CHANGE, STEADY_SIDES = 1.25, 3.0
#: A change under CLEAR_CHANGE is cut only where both sides keep at least SIDE_LANDINGS landings (a stride and a
#: half): a short take's strides wobble (a run of three strides speeding up by a fifth), and cutting there leaves
#: pieces too short to loop; a change of CLEAR_CHANGE or more (where one take meets the next) is cut however
#: short its sides.  Where the largest change of a stretch is such a small one, the stretch is not cut at all
#: (looking for the next largest instead cut the hours' sessions into more pieces: 10 loops fewer at 120 fps).
CLEAR_CHANGE, SIDE_LANDINGS = 2 * GAIT_CHANGE, 4
#: the scales of a stride's figures (period, speed, flight, double support: :func:`_stride_figures`' columns 0, 2,
#: 3, 4), in that order
_FIGURE_SCALE = np.array([STRIDE_STEPS[k] for k in ("period", "speed", "flight", "double support")])
#: ... and those columns
_FIGURE_COLUMNS = [0, 2, 3, 4]


def _figure_units(m: np.ndarray) -> np.ndarray:
    """The scales ``(4,)`` of the changes of stride figures whose median is ``m`` (period and speed as shares of
    it, flight and double support as shares of a stride), never zero."""
    return np.array([abs(m[0]), abs(m[1]), 1.0, 1.0]) * _FIGURE_SCALE + 1e-12


def _stride_poses(motion: Motion, frames: np.ndarray) -> np.ndarray | None:
    """Per stride of a chain whose landings are at ``frames`` (landing k to landing k+2): its mean pose (the
    joints' rotation vectors, no root) divided by the pose's swing over the chain's strides (the root of the
    median total variance within a stride), ``(n, D)``; ``None`` without rotation channels."""
    a, b = int(frames[0]), int(frames[-1])
    try:
        X, _ = pose_matrix(motion[a:b], rep="expmap", root_features="drop", normalize=False, weights=None)
    except MocycleError:
        return None
    f = np.asarray(frames, dtype=np.intp) - a
    lo, hi = f[:-2], f[2:]
    sums = np.concatenate([np.zeros((1, X.shape[1])), np.cumsum(X, axis=0)])
    squares = np.concatenate([np.zeros((1, X.shape[1])), np.cumsum(X * X, axis=0)])
    n = (hi - lo)[:, None].astype(np.float64)
    mean = (sums[hi] - sums[lo]) / n
    var = np.maximum((squares[hi] - squares[lo]) / n - mean * mean, 0.0).sum(axis=1)
    swing = float(np.sqrt(np.median(var)))
    return mean / swing if swing > 0 else None


def _gait_changes(strides: np.ndarray, poses: np.ndarray | None = None) -> set[int]:
    """The landings (indices into a chain's landings; a part boundary there starts a new part at that step)
    where a straight gait changes (:data:`STRIDE_STEPS`, :data:`GAIT_CHANGE`, :data:`STEADY_SIDES`): the
    medians of up to three strides ending at the landing and three starting there differ (``poses``: the
    strides' mean poses, :func:`_stride_poses`, a change of posture counting as one more figure).  The landing
    where they differ most is moved to the landing near it (up to three before, two after) whose parts would be
    steadier (:func:`_steadiest_cut`), and the strides on either side of the step it drops are looked at again,
    each side on its own: the stride that blends two takes, which sways the comparisons of the landings up to
    two strides on, is then in neither, and a take of a few strides between two others still shows both its
    changes.
    Turning strides are left out: a turn slows a walk, and the turn's own borders are cut by
    :func:`_turn_runs`."""
    return _changes_in(strides, poses, 0, strides.shape[0])


def _changes_in(strides: np.ndarray, poses: np.ndarray | None, lo: int, hi: int) -> set[int]:
    """:func:`_gait_changes` over strides ``lo .. hi-1`` of a chain only (landing indices of the chain)."""
    score = _change_scores(strides[lo:hi], None if poses is None else poses[lo:hi])
    if not score.size or not score.max() > 0:
        return set()
    b = 3 + int(np.argmax(score))  # the landing (of strides lo ..) where they differ most
    c = _steadiest_cut(b, strides[lo:hi], None if poses is None else poses[lo:hi])
    if float(score.max()) < CLEAR_CHANGE and min(c + 1, hi - lo + 1 - c) < SIDE_LANDINGS:
        return set()  # a small change that leaves a side too short to loop: the steps' own wobble, no new gait
    # strides ending by landing c, and those starting after the step it drops (landing c + 1)
    return {lo + c} | _changes_in(strides, poses, lo, lo + c - 1) | _changes_in(strides, poses, lo + c + 1, hi)


def _windows(values: np.ndarray) -> np.ndarray:
    """Windows of three strides ``(n, ..., 3)``: window ``k`` holds strides ``k-1 .. k+1`` of ``values (n, ...)``,
    NaN where they do not exist (the first and last window hold two)."""
    pad = np.full((1, *values.shape[1:]), np.nan)
    return np.lib.stride_tricks.sliding_window_view(np.concatenate([pad, values, pad]), 3, axis=0)


def _median3(windows: np.ndarray) -> np.ndarray:
    """The median over the last axis of windows of three values, a NaN among them left out (as
    ``np.nanmedian``, without its slow path): the middle value, or the mean of the two."""
    s = np.sort(windows, axis=-1)  # a NaN sorts last
    return np.where(np.isnan(s[..., 2]), (s[..., 0] + s[..., 1]) / 2, s[..., 1])


def _change_scores(strides: np.ndarray, poses: np.ndarray | None) -> np.ndarray:
    """For landings ``3 .. n-2`` of a chain of ``n`` strides (:func:`_gait_changes`), the size of the change
    between the strides before the landing (up to three, ending there) and after it (up to three, starting
    there) where it passes :data:`GAIT_CHANGE` and :data:`STEADY_SIDES` times the spread within either side,
    else 0 (and 0 where a stride of either side turns): ``(n - 4,)``."""
    n = strides.shape[0]
    if n < 5:
        return np.zeros(max(0, n - 4))
    landing = np.arange(3, n - 1)  # strides landing-4 .. landing-2 end by it, landing .. landing+2 start there
    before, after = landing - 3, landing + 1  # their windows (:func:`_windows`)
    figures = _windows(strides[:, _FIGURE_COLUMNS])
    turns = np.nan_to_num(_windows(np.abs(strides[:, 1])))
    m0 = _median3(figures[before])
    m1 = _median3(figures[after])
    unit = np.column_stack([m0[:, 0], m0[:, 1], np.ones_like(m0[:, :2])]) * _FIGURE_SCALE  # period, speed relative
    with np.errstate(invalid="ignore", divide="ignore"):
        # spread: the median deviation, blind to the one stride a blend may spoil
        squares = [np.sum(((m1 - m0) / unit) ** 2, axis=1),
                   np.sum((_median3(np.abs(figures[before] - m0[..., None])) / unit) ** 2, axis=1),
                   np.sum((_median3(np.abs(figures[after] - m1[..., None])) / unit) ** 2, axis=1)]
        if poses is not None:
            shapes = _windows(poses)
            p0, p1 = _median3(shapes[before]), _median3(shapes[after])
            squares[0] = squares[0] + np.sum((p1 - p0) ** 2, axis=1) / STRIDE_STEPS["pose"] ** 2
            for k, (side, m) in enumerate(((before, p0), (after, p1)), start=1):
                spread = _median3(np.linalg.norm(shapes[side] - m[..., None], axis=1))
                squares[k] = squares[k] + spread ** 2 / STRIDE_STEPS["pose"] ** 2
        change, within_b, within_a = (np.sqrt(x) for x in squares)
        turning = np.maximum(turns[before].max(axis=-1), turns[after].max(axis=-1)) > TURN_DEG
        ok = ~turning & (m0[:, 0] > 0) & (m0[:, 1] > 0) & (change > GAIT_CHANGE) & \
            (change > STEADY_SIDES * np.maximum(within_b, within_a))
    return np.where(ok, change, 0.0)


def _steadiest_cut(b: int, strides: np.ndarray, poses: np.ndarray | None) -> int:
    """Of landings ``b - 3 .. b + 2`` of a chain (its strides' figures ``strides``, :func:`_stride_figures`, and
    mean poses ``poses``), where to cut a gait that changes about landing ``b``: a cut at landing ``c`` drops the
    step from landing ``c`` to ``c + 1`` (the parts end at ``c`` and start at ``c + 1``), and the step that holds
    the change spoils both strides across it (strides ``c - 1`` and ``c``, stride ``k`` running from landing
    ``k`` to ``k + 2``); the cut whose parts' strides (two or three on either side) deviate least from their
    medians (in the scales of :data:`STRIDE_STEPS`) is the one that drops it.  Where the change scores
    (:func:`_change_scores`) peak says only roughly where that step is: they compare the medians of three
    strides ending at a landing and three starting there, and the two spoiled strides, two of a window's three,
    make its median theirs at landings ``c - 2 .. c - 1`` (the window after) and ``c + 2 .. c + 3`` (the window
    before), so the peak may lie anywhere from two landings before the step to three after it."""
    n = strides.shape[0]
    figures = strides[:, _FIGURE_COLUMNS]
    cost = {}
    for c in range(b - 3, b + 3):
        before, after = slice(max(0, c - 4), c - 1), slice(c + 1, min(n, c + 4))
        if min(before.stop - before.start, after.stop - after.start) < 2:  # one stride is always steady
            continue
        deviation = 0.0
        for side in (before, after):
            m = np.median(figures[side], axis=0)
            deviation += float(np.sum(np.abs(figures[side] - m) / _figure_units(m)))
            if poses is not None:
                deviation += float(np.sum(np.linalg.norm(poses[side] - np.median(poses[side], axis=0), axis=1))) \
                    / STRIDE_STEPS["pose"]
        cost[c] = deviation / ((before.stop - before.start) + (after.stop - after.start))
    return min(cost, key=lambda c: (cost[c], abs(c - b))) if cost else b


#: At most this many steps are dropped at either end of a chain of landings as a blend (:func:`_steady_ends`).
EDGE_STEPS = 2


def _edge_change(strides: np.ndarray, poses: np.ndarray | None, k: int, ref: slice) -> float:
    """How far stride ``k`` of a chain lies from the median of its strides ``ref`` (their figures,
    :func:`_stride_figures`, and mean poses, :func:`_stride_poses`), in the scales of :data:`STRIDE_STEPS`."""
    figures = strides[:, _FIGURE_COLUMNS]
    m = np.median(figures[ref], axis=0)
    square = float(np.sum(((figures[k] - m) / _figure_units(m)) ** 2))
    if poses is not None:
        square += float(np.sum((poses[k] - np.median(poses[ref], axis=0)) ** 2)) / STRIDE_STEPS["pose"] ** 2
    return float(np.sqrt(square))


def _steady_ends(strides: np.ndarray, poses: np.ndarray | None, cuts: Collection[int] = ()) -> tuple[int, int]:
    """The strides ``lo .. hi-1`` of a chain that its gait parts may hold (the chain's landings ``lo .. hi+1``):
    at either end of the chain, up to :data:`EDGE_STEPS` strides that differ from the median of the three
    strides inside them by more than :data:`GAIT_CHANGE` (:func:`_edge_change`) are left out, one step at a
    time.  Where one take meets the next the steps about the join blend the two (a stride longer or shorter
    than either's, a speed between them, another posture) and the landings may run on a step or two into the
    next take before its tempo breaks the chain.  The strides compared lie in the end's own part (``cuts``: the
    landings where the chain's gait changes, :func:`_gait_changes`, or its steps change from walk to run) and
    that part keeps three; a stride that turns (:data:`TURN_DEG`) is never left out (a turn changes a gait's
    tempo on its own)."""
    n = strides.shape[0]
    first = min(cuts, default=n + 1) - 1  # the strides of the first part: 0 .. first-1; of the last: last .. n-1
    last = max(cuts, default=-1) + 1
    lo, hi = 0, n

    def blended(k: int, ref: slice) -> bool:
        if np.any(np.abs(strides[[k, *range(n)[ref]], 1]) > TURN_DEG):
            return False
        return _edge_change(strides, poses, k, ref) > GAIT_CHANGE

    while lo < EDGE_STEPS and first - lo > 3 and blended(lo, slice(lo + 1, lo + 4)):
        lo += 1
    while n - hi < EDGE_STEPS and hi - max(last, lo) > 3 and blended(hi - 1, slice(hi - 4, hi - 1)):
        hi -= 1
    return lo, hi


def _joins_at_turns(strides: np.ndarray, poses: np.ndarray | None, cuts: Collection[int] = ()) -> set[int]:
    """Landings (chain indices, as :func:`_gait_changes`') where one take meets the next within
    :data:`EDGE_STEPS` + 1 strides of a turn: a take that ends walking out of a turn, joined to a walk of the same
    tempo and posture (one performer's session), or a walk joined to a take that walks into a turn.  The change
    test needs two straight strides on either side of a join, and a turn's strides are none; so the strides
    next to the turn are held against the three straight strides beyond them (:func:`_edge_change`), and where
    one or two differ by more than :data:`GAIT_CHANGE` (the blend of the join: a stride longer or shorter than
    either take's, another speed, another posture), the straight part beyond them starts where the last of them
    ends (after a turn), or the one before them ends where the first begins (before a turn).  Strides that turn
    (:data:`TURN_DEG`) and strides across a cut already made are never held against."""
    n = strides.shape[0]
    turning = np.abs(strides[:, 1]) > TURN_DEG
    width = EDGE_STEPS + 1
    out: set[int] = set()

    def steady(strides_in: range) -> bool:  # straight strides that no cut crosses
        a, b = strides_in.start, strides_in.stop
        return a >= 0 and b <= n and not turning[a:b].any() and not any(a - 1 <= c < b for c in cuts)

    def differs(k: int, ref: range) -> bool:
        return _edge_change(strides, poses, k, slice(ref.start, ref.stop)) > GAIT_CHANGE

    for s in range(1, n):
        if turning[s - 1] and not turning[s]:  # straight strides s .. after a turn
            window, ref = range(s, s + width), range(s + width, s + width + 3)
            if steady(range(s, ref.stop)):
                ends = [k for k in window if differs(k, ref)]
                if ends:
                    out.add(ends[-1] + 1)  # the part after starts at landing ends[-1] + 2
        if not turning[s - 1] and turning[s]:  # straight strides .. s - 1 before a turn
            window, ref = range(s - width, s), range(s - width - 3, s - width)
            if steady(range(ref.start, s)):
                starts = [k for k in window if differs(k, ref)]
                if starts:
                    out.add(starts[0])  # the part before ends at landing starts[0]
    return out


#: A join of two takes of one gait at one tempo and posture shows in no stride figure: the cross-fade keeps the
#: landings' rhythm.  What it breaks is the legs' repeat: before it the legs are like themselves a stride later,
#: after it too, but a stride's frames before it are unlike the stride after it when the second take starts at
#: another phase.  A landing is such a break where the legs' unlikeness over the stride straddling it (each frame
#: against the frame a stride later, :func:`_unlike`'s measure) is at least BREAK_UNLIKE and STEADY_SIDES times
#: that over the stride before it and the stride after it (a join near one phase is as seamless as the take: no
#: break, nothing a loop across it would spoil).
BREAK_UNLIKE = 0.2


def _phase_breaks(motion: Motion, frames: np.ndarray, strides: np.ndarray, cuts: Collection[int] = ()) -> set[int]:
    """Landings (chain indices, as :func:`_gait_changes`') where the legs stop repeating across one stride and
    repeat again on either side (:data:`BREAK_UNLIKE`): where one take of a gait meets another of the same
    tempo and posture at another phase.  ``frames``: the chain's landing frames; ``strides``: its figures
    (:func:`_stride_figures`).  A break between landings ``c`` and ``c + 1`` is cut at ``c`` (the step between
    them dropped); each step is looked at with the stride of the strides before it, of those after it and of
    both (a chain may hold takes of several tempos, and a lag a frame off at 30 fps hides a break), only where
    the strides of its windows are straight and no cut is made at or next to it."""
    n = strides.shape[0]
    if n < 5:
        return set()
    f0 = int(frames[0])
    X = _leg_features(motion, f0, int(frames[-1]) + 1)
    if X is None:
        return set()
    turning = np.abs(strides[:, 1]) > TURN_DEG
    scores = []
    for c in range(1, n - 1):  # the step from landing c to c + 1 (strides c - 1 and c hold it)
        # the stride of the strides beyond those the step's blend may spoil (c - 2 .. c + 1): before the step,
        # after it, and both (the two may be takes of a walk and a run, not yet cut apart)
        sides = [strides[max(0, c - 5):max(0, c - 2), 0], strides[c + 2:c + 5, 0]]
        lags = {int(round(float(np.median(x)))) for x in (*sides, np.concatenate(sides)) if x.size}
        best = max((_break_score(X, frames, c, P, f0) for P in sorted(lags) if P >= 2), default=0.0)
        if best >= STEADY_SIDES:
            lo = int(np.searchsorted(frames, frames[c] - 2 * max(lags), side="right")) - 1  # strides in the windows
            hi = int(np.searchsorted(frames, frames[c + 1] + 2 * max(lags), side="left"))
            if not turning[max(lo, 0):min(hi, n)].any():
                scores.append((best, c))
    blocked = list(cuts)
    out: set[int] = set()
    for _, c in sorted(scores, reverse=True):
        if any(abs(x - c) <= 1 for x in blocked):
            continue
        out.add(c)
        blocked.append(c)
    return out


def _break_score(X: np.ndarray, frames: np.ndarray, c: int, P: int, f0: int) -> float:
    """How much more the legs ``X`` (the chain's frames from ``f0`` on) are unlike themselves ``P`` frames later
    over a stride straddling a frame of the step from landing ``c`` to ``c + 1`` than over the stride before and
    the stride after it (:func:`_phase_breaks`), the most over the step's frames; 0 where the windows do not fit
    in the chain or the straddling stride is alike (:data:`BREAK_UNLIKE`)."""
    a, b = max(0, int(frames[c]) - 2 * P - f0), min(X.shape[0], int(frames[c + 1]) + 2 * P - f0)
    if b - a < 4 * P + 1:
        return 0.0
    Y = X[a:b]  # two strides either side of the step (those of its frames whose windows fit in the chain)
    var = float(Y.var(axis=0).sum())
    if not var > 0:
        return 0.0
    step = _lag_steps(Y, P) / (2.0 * var)  # frame s against s + P
    sums = np.concatenate([[0.0], np.cumsum(step)])
    t = np.arange(2 * P, Y.shape[0] - 2 * P + 1)  # a break at t: strides [t-2P, t-P), [t-P, t), [t, t+P)
    before, across, after = ((sums[t + k * P] - sums[t + (k - 1) * P]) / P for k in (-1, 0, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        score = np.where(across >= BREAK_UNLIKE, across / np.maximum(before, after), 0.0)
    return float(score.max()) if score.size else 0.0


def stride_rate(heading: np.ndarray, period: float, start: int, stop: int) -> np.ndarray:
    """The hips' turning rate ``(stop - start,)`` in degrees per stride: the heading's change over one stride
    (``period`` frames) about each frame, where the hips' sway within a stride cancels; near the take's ends the
    stride is the first or last one inside it."""
    T = heading.size
    span = min(max(2, int(round(period))), T - 1)
    t = np.arange(start, stop)
    lo = np.clip(t - span // 2, 0, T - 1 - span)
    return (heading[lo + span] - heading[lo]) * (period / span)


def _turn_runs(rate: np.ndarray, period: float, least: float) -> list[tuple[int, int, int]]:
    """A gait part's frames as runs ``(start, stop, way)`` by the hips' turning rate ``rate`` (deg per stride):
    ``way`` 0 straight (under :data:`TURN_DEG`), +1 / -1 a turn's core to the left / right (at least
    :data:`TURN_CORE_SHARE` of that turn's fastest rate), 2 a turn's slow start or end (a transition).  A core
    shorter than ``least`` frames (the cycles a loop needs) grows into its turn's slower frames, evenly on both
    sides, as far as they turn by more than :data:`TURN_DEG`: a sharp turn of a stride and a half is still a
    turn to loop.  Runs shorter than a quarter of a stride take the way of their longer neighbour.

    A moment's swing past :data:`TURN_DEG` that turns the hips only a few degrees in all is kept as a turn too
    (a piece too short to loop): where one take meets the next the blended heading swings so, and the pieces
    keep a loop from spanning the join.  Treating such swings as straight looped one more run take in the
    120 fps hour but made two loops over a border in the 4- and 15-minute sessions (2026-12-08)."""
    n = rate.size
    way = np.where(np.abs(rate) >= TURN_DEG, np.sign(rate), 0).astype(np.int8)
    label = np.zeros(n, dtype=np.int8)
    for a, b, w in _value_runs(way):
        if w == 0:
            continue
        r = np.abs(rate[a:b])
        core = np.flatnonzero(r >= max(TURN_DEG, TURN_CORE_SHARE * float(r.max())))
        c0, c1 = a + int(core[0]), a + int(core[-1]) + 1
        while c1 - c0 < least and (c0 > a or c1 < b):  # the slower side first: the core stays centred
            if c0 > a and (c1 >= b or abs(rate[c0 - 1]) >= abs(rate[c1])):
                c0 -= 1
            else:
                c1 += 1
        label[a:b] = 2
        label[c0:c1] = w
    short = max(1, int(round(period / 4)))
    runs = _value_runs(label)
    while len(runs) > 1:
        k = min(range(len(runs)), key=lambda i: runs[i][1] - runs[i][0])
        a, b, _ = runs[k]
        if b - a >= short:
            break
        nbrs = [runs[i] for i in (k - 1, k + 1) if 0 <= i < len(runs)]
        label[a:b] = max(nbrs, key=lambda r: r[1] - r[0])[2]
        runs = _value_runs(label)
    return runs


def _value_runs(values: np.ndarray) -> list[tuple[int, int, int]]:
    """Runs ``(start, stop, value)`` of equal values of an integer array, in order."""
    values = np.asarray(values)
    if values.size == 0:
        return []
    edges = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges, [values.size]])
    return [(int(a), int(b), int(values[a])) for a, b in zip(starts, stops, strict=True)]


#: A turn's core grows to at least this many strides when the turn lasts that long (:func:`_turn_runs`): the
#: default ``min_periods`` (1.2) with room for a stride phase fitted a little longer than the landings say.
TURN_LEAST = 1.3


def _split_turns(part: Activity, heading: np.ndarray, path: np.ndarray, fps: float) -> list[Activity]:
    """A gait part (``kind`` ``"walk"`` or ``"run"``) cut where the hips start and stop turning
    (:func:`_turn_runs`): straight parts, turning parts that hold the turn's core only, and the turn's slow
    start and end as transitions."""
    gait = part.kind
    names = {0: f"{gait} straight", 1: f"{gait} turning left", -1: f"{gait} turning right", 2: "transition"}
    runs = _turn_runs(stride_rate(heading, part.period_frames, part.start, part.stop), part.period_frames,
                      np.ceil(TURN_LEAST * part.period_frames))
    out = []
    for k, (a, b, way) in enumerate(runs):
        a, b = part.start + a, part.start + b
        own = {side: [f for f in frames if a <= f < b] for side, frames in part.landings.items()}
        reason = ""
        if way == 2:
            when = "start" if k + 1 < len(runs) and runs[k + 1][2] in (1, -1) else "end"
            reason = f"the turn's {when}: the hips turn slower than {TURN_CORE_SHARE:.0%} of the turn's fastest"
        out.append(Activity(start=a, stop=b, kind=names[way], limbs="legs" if way != 2 else "none",
                            period_frames=part.period_frames,
                            speed=float(np.linalg.norm(path[b - 1] - path[a])) * fps / max(b - 1 - a, 1),
                            turn_deg=float(heading[b - 1] - heading[a]),
                            landings={side: v for side, v in own.items() if v}, reason=reason))
    return out


def segment_activities(motion: Motion, *, min_periods: float = MIN_PERIODS, joints=None, step: int | None = None,
                       map=map, **phase_options) -> Activities:
    """Cut ``motion`` into steady parts (module notes); ``min_periods``: cycles a part needs to be looped.

    ``joints``, ``step`` and ``phase_options`` (``classes``, ``pca``, ``delay``, ``n_landmarks``) are
    :func:`~mocycle.phase.find_phase`'s, used inside the parts without gait (``joints``: the joints those parts'
    periodic motion is found on, instead of the moving arm joints or the whole body; ``step``: the phase found
    on every ``step``-th frame).  Gait parts take their phase from the landings, or, when ``joints`` are given,
    from the cohomology of those joints inside the part.  ``step`` ``None``: :func:`phase_step` of the take's
    frame rate (every frame where the feet land, :data:`PHASE_RATE`).  ``map``: how the stretches between gait
    parts, which are looked at each on its own, are mapped (a process pool's ``map`` looks at them side by side;
    the parts are the same).  Without feet found by name, the whole take is looked at as frames without gait
    (arms, then the whole body, region by region).  Every part that loops (``loop``)
    holds at least ``min_periods`` cycles of its own ``periodic`` phase, and a part without gait at least
    :data:`MIN_REPEATS`.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> acts = segment_activities(synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion)
    >>> [(p.kind, p.start, p.stop, round(p.period_frames)) for p in acts.parts]
    [('walk straight', 0, 300, 60)]
    """
    T, fps = motion.n_frames, motion.fps
    min_periods = _validate.real("min_periods", min_periods, 1.0)
    if joints is not None:
        motion.skeleton.select(joints)  # a joint the rig lacks is the caller's mistake: said once, here
    step = None if step is None else _validate.integer("step", step, 1)  # None: :func:`_phase_step_in`'s
    options = {"joints": joints, "step": step, **phase_options}
    landings = find_landings(motion)
    if landings is None:
        parts = _other(motion, 0, T, min_periods, False, options)
        _decide(parts, min_periods)
        parts = _or_one_cycle(motion, parts, None)
        return Activities(parts=parts, n_frames=T, frame_time=motion.frame_time, feet=False,
                          reason="the rig's feet were not found by name: the take is looked at without gait; "
                                 + _listing(parts), landings=None)
    heading = heading_degrees(motion)
    path = _horizontal_path(motion)
    body = _body_height(motion)
    parts = []
    stepped = []  # the landings of the gait chains: a stride phase is a line through these only
    changes: set[int] = set()  # the landings where a gait changes: the parts beside them reach no further
    blends: list[tuple[int, int]] = []  # the steps left out at a chain's ends (:func:`_steady_ends`)
    for chain in _gait_chains(landings, fps, least=2):
        stepped.append(chain)
        a, b = int(landings.frames[chain[0]]), int(landings.frames[chain[-1]])
        if _legs_stand(motion, a, b + 1):
            continue  # contacts that flicker while the legs stand are no steps
        if chain.size == 2:  # one step: a take (or a part) of little more than a stride
            short = _one_step_part(motion, chain, landings, heading, path, body)
            if short is not None:
                parts.append(short)
            continue
        strides = _stride_figures(chain, landings, heading, path, fps)
        poses = _stride_poses(motion, landings.frames[chain])
        cuts = _gait_changes(strides, poses)
        cuts |= _joins_at_turns(strides, poses, cuts)
        cuts |= _phase_breaks(motion, landings.frames[chain], strides, cuts)
        kinds = _step_gaits(strides, body)
        walk_run = {j for j in range(1, len(kinds)) if kinds[j][0] != kinds[j - 1][0]}
        lo, hi = _steady_ends(strides, poses, cuts | walk_run)
        ends = [(0, lo)] if lo > 0 else []
        if hi < strides.shape[0]:
            ends.append((hi + 1, chain.size - 1))
        for e0, e1 in ends:  # blended steps at an end: a transition; the parts beside it reach no further
            blends.append((int(landings.frames[chain[e0]]), int(landings.frames[chain[e1]])))
            changes.update(blends[-1])
        if (lo, hi) != (0, strides.shape[0]):  # the steps at the new ends lie in fewer strides
            chain, strides = chain[lo:hi + 2], strides[lo:hi]
            cuts = {c - lo for c in cuts}
            kinds = _step_gaits(strides, body)
        f = landings.frames[chain]
        i = 0
        while i < len(kinds):
            j = i + 1
            while j < len(kinds) and kinds[j][0] == kinds[i][0] and j not in cuts and \
                    abs(kinds[j][1] / float(np.median([k[1] for k in kinds[i:j]])) - 1) <= TEMPO_CHANGE:
                j += 1
            # steps i .. j-1: landings f[i] .. f[j]
            parts.append(_gait_part(kinds[i][0], f, chain, i, j, landings, strides, heading, path, fps))
            # where the gait changes, the step across the change belongs to neither part (a blend of the two)
            if j in cuts and j + 2 < len(kinds):
                changes.update((int(f[j]), int(f[j + 1])))
                i = j + 1
            else:
                i = j
    # steps that land in turn but whose legs do not repeat a stride later (a wander, a stumble) are no gait
    parts = [p for p in parts if _legs_repeat_in(motion, p)]
    parts.sort(key=lambda p: p.start)
    _reach(motion, parts, T, changes)
    parts = [q for p in parts for q in (_split_turns(p, heading, path, fps) if " " not in p.kind else [p])]
    parts = _with_blends(parts, blends)
    parts = _fill(motion, parts, landings, min_periods, options, map)
    keep = np.sort(np.concatenate(stepped)) if stepped else np.zeros(0, dtype=np.intp)
    steps = Landings(landings.frames[keep], landings.foot[keep], landings.sides, landings.down)
    gait = [p for p in parts if p.gait and p.n_periods >= min_periods]
    if joints is None:  # each part's phase from its own frames and the landings near them: side by side
        jobs = [_GaitJob(motion[p.start:p.stop], _rebased_part(p), _steps_near(steps, p)) for p in gait]
        for p, (periodic, period) in zip(gait, map(_gait_job, jobs), strict=True):
            p.periodic, p.period_frames = periodic, period
    else:
        for p in gait:
            _asked_phase(motion, p, min_periods, options)
    _decide(parts, min_periods)
    parts = _second_look(motion, parts, landings, min_periods, options, map, changes)
    parts = _without_slivers(parts, fps)
    parts = _or_one_cycle(motion, parts, landings)
    return Activities(parts=parts, n_frames=T, frame_time=motion.frame_time, feet=True, reason=_listing(parts),
                      landings=landings)


def phase_step(fps: float) -> int:
    """The frames from one the cohomology looks at to the next in a take of ``fps`` frames a second when not told
    (:data:`PHASE_RATE`): 1 up to 45 fps, 2 at 60, 4 at 120."""
    return max(1, int(round(float(fps) / PHASE_RATE)))


def _phase_step_in(step: int | None, fps: float, stepping: bool = False) -> int:
    """The step the cohomology takes in a stretch: ``step`` when one was asked for, else every frame where the
    feet land (``stepping``) and :func:`phase_step` elsewhere (:data:`PHASE_RATE`)."""
    if step is not None:
        return int(step)
    return 1 if stepping else phase_step(fps)


#: A take is one cycle when its wrap (last frame to first, or, when the last frame repeats the first, the one
#: before it) changes the joints' velocity by no more than WRAP_JUMP times its median step, and it moves
#: through the wrap: its speed at its ends at least MOVING_WRAP of its 90th-percentile speed (a gesture that
#: starts and ends at rest does not).
WRAP_JUMP, MOVING_WRAP = 1.5, 0.4
#: A last frame closer to the first than this share of the median step repeats it (a closing frame).
CLOSING_FRAME = 0.25


def one_cycle(motion: Motion) -> int | None:
    """The period (frames) of a take that is one cycle of its own motion (a game clip: a walk or run of one
    stride, often with a closing frame that repeats the first), or ``None``: the take is no such clip
    (:data:`WRAP_JUMP`, :data:`MOVING_WRAP`; the joints' rotations decide, not the root's travel).  Of the
    two readings, an open cycle of all the frames or a cycle closed by its last frame, the one whose wrap
    changes the velocity less.  A take like itself a third to four fifths of its length later holds more
    than one cycle and is no such clip.  A take longer than :data:`MAX_REPEAT_S` is no cycle either (and the
    search for a repeat within it, over lags up to its length, would cost its length squared: minutes for a
    few minutes of capture where nothing loops)."""
    T = motion.n_frames
    if T < 8 or T > MAX_REPEAT_S * motion.fps + 1:
        return None
    X, _ = pose_matrix(motion, rep="expmap", root_features="drop", joints=None, normalize=False, weights=None)
    if not float(np.degrees(np.sqrt(X.var(axis=0).sum()))) >= STILL_DEG:
        return None  # nothing moves
    steps = np.linalg.norm(np.diff(X, axis=0), axis=1)
    typical = float(np.median(steps))
    if not typical > 0:
        return None
    ends = 0.25 * float(steps[:2].sum() + steps[-2:].sum())
    if ends < MOVING_WRAP * float(np.percentile(steps, 90)):
        return None  # it rests where it starts and ends: a gesture, not a cycle

    lags = np.arange(max(2, int(ONE_CYCLE_LAGS[0] * T)), int(ONE_CYCLE_LAGS[1] * T) + 1)
    if lags.size and min(_unlike(X, int(lag)) for lag in lags) < UNLIKE_ONE_STEP:
        return None  # it repeats within itself: more than one cycle (the parts say how many)

    def jump(last: int) -> float:  # frames 0 .. last as the cycle: the velocity change across its wrap
        into, out = X[0] - X[last], X[1] - X[0]
        return float(np.linalg.norm(into - (X[last] - X[last - 1])) + np.linalg.norm(out - into))

    if float(np.linalg.norm(X[-1] - X[0])) <= CLOSING_FRAME * typical:  # the last frame repeats the first
        return T - 1 if jump(T - 2) <= 2 * WRAP_JUMP * typical else None
    best, period = min((jump(T - 1), T), (jump(T - 2), T - 1))
    return period if best <= 2 * WRAP_JUMP * typical else None


def _or_one_cycle(motion: Motion, parts: list[Activity], landings: Landings | None) -> list[Activity]:
    """``parts``, or, when none of them loops and the whole take is one cycle (:func:`one_cycle`), the take as
    one part that is looped as it is: its kind from its feet (a walk or run of one stride) or its limbs."""
    if any(p.loop for p in parts):
        return parts
    period = one_cycle(motion)
    if period is None:
        return parts
    T = motion.n_frames
    kind, limbs = "periodic", "all"
    own: dict[str, list[int]] = {}
    if landings is not None and landings.frames.size:
        for f, k in zip(landings.frames.tolist(), landings.foot.tolist(), strict=True):
            own.setdefault(landings.sides[k], []).append(int(f))
        if len(own) >= 2:  # both feet land in it: a stride of a gait
            down = landings.down
            path = _horizontal_path(motion)
            speed = float(np.linalg.norm(path[-1] - path[0])) * motion.fps / max(T - 1, 1)
            turn = float(heading_degrees(motion)[-1] - heading_degrees(motion)[0])
            gait = gait_of(float(np.mean(down == 0)), float(np.mean(down >= 2)), speed, _body_height(motion))
            way = "straight" if abs(turn) <= TURN_DEG else ("turning left" if turn > 0 else "turning right")
            kind, limbs = f"{gait} {way}", "legs"
    if kind == "periodic" and _legs_stand(motion, 0, motion.n_frames):
        kind = "arms"
    closing = period == T - 1
    why = (f"the take is one cycle of {period} frames: its last frame repeats its first (a closing frame), looped "
           f"as it is" if closing else f"the take is one cycle of {period} frames: its last pose leads back to "
           f"its first, looped as it is")
    x = np.arange(T, dtype=np.float64) / period
    part = Activity(start=0, stop=T, kind=kind, limbs=limbs, period_frames=float(period), loop=True, reason=why,
                    landings=own, one_cycle=True,
                    periodic=line_periodic(x, period, motion.frame_time, "one cycle", limbs, why))
    return [part]


def _with_blends(parts: list[Activity], blends: list[tuple[int, int]]) -> list[Activity]:
    """The parts with the frames of ``blends`` (the steps left out at a chain's ends, :func:`_steady_ends`) that
    no part holds as transitions, in frame order: looked at for no other motion (they blend two takes)."""
    out = list(parts)
    for a, b in blends:
        for p in parts:  # a neighbour that reached into the blend keeps what it holds
            if p.start <= a < p.stop:
                a = p.stop
            if p.start < b <= p.stop:
                b = p.start
        if b > a:
            out.append(Activity(start=a, stop=b, kind="transition", limbs="none",
                                reason="steps where one take meets another: a blend of the two, no one motion"))
    return sorted(out, key=lambda q: q.start)


#: A part that does not loop and lasts under this many seconds is merged into a neighbour that does not loop
#: either (:func:`_without_slivers`).
SLIVER_S = 0.1


def _without_slivers(parts: list[Activity], fps: float) -> list[Activity]:
    """``parts`` with each sliver (a part that does not loop, under :data:`SLIVER_S`: the frame or two left
    between two cuts) merged into the part before it, or else the part after it, when that part does not loop
    and has no phase of its own either; the merged part keeps its kind and reason.  A sliver between two parts
    that loop stays as it is (their borders are where their own frames end)."""
    def takes(q: Activity) -> bool:
        return not q.loop and q.periodic is None

    out: list[Activity] = []
    for k, p in enumerate(parts):
        if takes(p) and p.n_frames < SLIVER_S * fps:
            into = None
            if out and takes(out[-1]):
                into = out[-1]
            elif k + 1 < len(parts) and takes(parts[k + 1]):
                into = parts[k + 1]
            if into is not None:
                into.start, into.stop = min(into.start, p.start), max(into.stop, p.stop)
                into.landings = {side: sorted(set(into.landings.get(side, [])) | set(p.landings.get(side, [])))
                                 for side in {**into.landings, **p.landings}}
                continue
        out.append(p)
    return out


def _second_look(motion: Motion, parts: list[Activity], landings: Landings, min_periods: float, options: dict,
                 map=map, changes: Collection[int] = ()) -> list[Activity]:
    """Frames where steps were seen but no gait part loops (landings missed on a rig whose feet slide, a
    stumble) looked at again as frames without gait (:func:`_other`, through ``map``): each run of neighbouring
    parts that do not loop, holding steps and lasting :data:`MIN_OTHER_S` or more, is replaced by what that
    finds when it finds a motion that repeats there; otherwise the parts stay as they were.  A run ends where a
    part starts at a landing of ``changes`` (where the gait was seen to change): what is looked at again lies on
    one side of every change."""
    runs: list[list[Activity]] = []
    k = 0
    while k < len(parts):
        j = k
        while j < len(parts) and not parts[j].loop and (j == k or parts[j].start not in changes):
            j += 1
        runs.append(parts[k:j] if j > k else [parts[k]])
        k = max(j, k + 1)
    again = [r for r in runs if not r[0].loop and any(p.landings for p in r)
             and (r[-1].stop - r[0].start) * motion.frame_time >= MIN_OTHER_S]
    found = map(_gap_parts, [_Gap(motion[r[0].start:r[-1].stop], r[0].start, min_periods, True, options,
                                  _steps_in(landings, r[0].start, r[-1].stop)) for r in again])
    instead = {}
    for r, new in zip(again, found, strict=True):
        _decide(new, min_periods)
        if any(p.loop for p in new):
            instead[id(r)] = new
    return [p for r in runs for p in instead.get(id(r), r)]


def _listing(parts: list[Activity]) -> str:
    kinds = ", ".join(f"{p.kind} {p.start}-{p.stop}" for p in parts)
    return f"{len(parts)} part(s): {kinds}" if parts else "no part"


@dataclass(frozen=True)
class _GaitJob:
    """A gait part's frames, the part (its own frames) and the landings of the steps near it: what its phase
    needs (sent as it is to another process)."""

    motion: Motion
    part: Activity
    landings: Landings


def _rebased_part(p: Activity) -> Activity:
    return replace(p, start=0, stop=p.n_frames, landings={k: [f - p.start for f in v] for k, v in p.landings.items()})


def _steps_near(steps: Landings, p: Activity) -> Landings:
    """The landings of ``steps`` within a stride of part ``p``, in the part's frames."""
    P = p.period_frames if np.isfinite(p.period_frames) else p.n_frames
    near = (steps.frames >= p.start - P) & (steps.frames <= p.stop + P)
    return Landings(steps.frames[near] - p.start, steps.foot[near], steps.sides, steps.down[p.start:p.stop])


def _gait_job(job: _GaitJob) -> tuple[object, float]:
    """:func:`_gait_phase` of one gait part: its ``(periodic, period_frames)``."""
    p = job.part
    _gait_phase(job.motion, p, job.landings)
    return p.periodic, p.period_frames


def _gait_phase(motion: Motion, p: Activity, landings: Landings) -> None:
    """A gait part's phase (``periodic``) and period: a line through the landings of its steps (``landings``:
    those of the gait chains, not a foot that comes down beside them; :func:`stride_phase`),
    its period checked by the legs' self-similarity (:func:`legs_check`); for one step, the legs' own."""
    try:
        x, period = stride_phase(p, landings.frames, landings.foot, p.start, p.stop)
    except MocycleError:  # fewer than three landings near: one step, the legs' self-similarity
        x = (np.arange(p.start, p.stop) - p.start) / p.period_frames
        p.periodic = line_periodic(x, p.period_frames, motion.frame_time, "legs self-similarity", "legs",
                                   f"the legs' self-similarity: the part holds one step, its legs are most "
                                   f"alike {p.period_frames:.2f} frames apart")
        return
    legs, why = legs_check(motion, p.start, p.stop, period)
    step = p.period_frames / 2.0
    n = int(np.count_nonzero((landings.frames >= p.start - step) & (landings.frames <= p.stop + step)))
    if np.isfinite(legs):  # a landing seen early or late: the legs' own repeat decides the period
        x = (x - x[0]) * period / legs + x[0]
        p.periodic = line_periodic(x, legs, motion.frame_time, "legs self-similarity", "legs",
                                   f"the legs' self-similarity: {why} (the {n} landings said {period:.2f})")
        p.period_frames = legs
    else:
        p.periodic = line_periodic(x, period, motion.frame_time, "strides", "legs",
                                   f"the strides: landings of each foot {period:.2f} frames apart (a line through "
                                   f"{n} landings; {why})")
        p.period_frames = period


def _asked_phase(motion: Motion, p: Activity, min_periods: float, options: dict) -> None:
    """A gait part's phase found as asked (``options["joints"]``): the cohomology of the part's frames on those
    joints (:func:`~mocycle.phase.find_phase`), the periodic motion covering most of them; the loop checks then
    hold it against the strides."""
    options = dict(options)
    step = _phase_step_in(options.pop("step", None), motion.fps, stepping=True)  # a gait: its feet land
    try:
        found = find_phase_every(motion[p.start:p.stop], step, min_periods=min_periods, **options).classes
    except MocycleError as exc:
        found, why = [], str(exc)
    else:
        why = "no periodic motion found on the joints asked"
    if not found:
        p.periodic = None
        p.reason = f"{p.kind}: {why}"
        return
    p.periodic = max(found, key=lambda c: len(c.frames()))  # on the part's frames; it winds in its excitation
    p.period_frames = p.periodic.period_frames


def _decide(parts: list[Activity], min_periods: float) -> None:
    """Which parts loop, the same rule for every kind: a phase of its own, at least ``min_periods`` cycles of it
    (:data:`MIN_REPEATS` without gait: seen to repeat) and so a period shorter than the part; the reason in
    plain words for every part that does not."""
    for p in parts:
        if p.kind in ("gesture", "standing", "transition") and not p.gait:
            p.loop = False
            continue
        least = min_periods if p.gait or p.in_step else max(min_periods, MIN_REPEATS)
        n = p.n_periods
        p.loop = bool(p.periodic is not None and np.isfinite(n) and n >= least)
        if p.loop:
            if p.gait and not p.in_step:
                p.reason = ""
            continue
        if p.gait:
            if np.isfinite(n):
                p.reason = (f"{p.kind} for only {n:.1f} stride(s): too short for a loop (at least {least:g} "
                            f"wanted)")
            p.kind = "transition" if len(parts) > 1 else p.kind
        elif np.isfinite(n):
            p.reason = (f"{p.kind}: only {n:.1f} periods of {p.period_frames:.1f} frames: it is not seen to repeat "
                        f"(at least {least:g} wanted)")
            p.kind = "gesture"
        p.periodic = None


def _gait_part(kind, f, chain, i, j, landings, strides, heading, path, fps) -> Activity:
    a, b = int(f[i]), int(f[j])
    rows = strides[max(0, i - 1): j]  # the strides that overlap steps i .. j-1
    period = float(np.median(rows[:, 0]))
    own: dict[str, list[int]] = {}
    for k in range(i, j + 1):
        own.setdefault(landings.sides[landings.foot[chain[k]]], []).append(int(f[k]))
    return Activity(start=a, stop=b, kind=kind, limbs="legs", period_frames=period,
                    speed=float(np.linalg.norm(path[b] - path[a])) * fps / max(b - a, 1),
                    turn_deg=float(heading[b] - heading[a]), landings=own)


def _one_step_part(motion: Motion, chain, landings: Landings, heading, path, body) -> Activity | None:
    """A gait part from one step (two landings, one of each foot): its period from the legs' self-similarity
    near twice the step (:func:`short_period`), its phase a line at that period; ``None`` when the legs do
    not repeat there."""
    fps = motion.fps
    a, b = (int(x) for x in landings.frames[chain])
    reach = b - a
    lo, hi = max(0, a - 2 * reach), min(motion.n_frames, b + 2 * reach)
    period, unlike = short_period(motion, 2.0 * reach, lo, hi)
    if not (np.isfinite(period) and unlike < UNLIKE_ONE_STEP):
        return None
    speed = float(np.linalg.norm(path[hi - 1] - path[lo])) * fps / max(hi - 1 - lo, 1)
    turn = float(heading[hi - 1] - heading[lo])
    per_stride = turn / (hi - 1 - lo) * period
    way = "straight" if abs(per_stride) <= TURN_DEG else ("turning left" if per_stride > 0 else "turning right")
    down = landings.down[lo:hi]
    gait = gait_of(float(np.mean(down == 0)), float(np.mean(down >= 2)), speed, body)
    own: dict[str, list[int]] = {}
    for k in chain:
        own.setdefault(landings.sides[landings.foot[k]], []).append(int(landings.frames[k]))
    return Activity(start=a, stop=b, kind=f"{gait} {way}", limbs="legs", period_frames=period, speed=speed,
                    turn_deg=turn, landings=own,
                    periodic=None, reason=f"one step: the period from the legs' self-similarity ({unlike:.2f})")


def _leg_features(motion: Motion, start: int, stop: int) -> np.ndarray | None:
    """The legs' rotation vectors ``(stop - start, D)`` (no root, not normalised), ``None`` without legs."""

    try:
        X, _ = pose_matrix(motion[start:stop], rep="expmap", root_features="drop", joints="legs", normalize=False,
                           weights=None)
    except MocycleError:
        return None
    return X


def _unlike(X: np.ndarray, lag: int) -> float:
    """Mean squared difference of the rows of ``X`` ``lag`` apart over twice its total variance: about 0 where
    the motion repeats at that lag, about 1 or more where it does not."""
    return _unlike_var(X, lag, float(X.var(axis=0).sum()))


def _unlike_var(X: np.ndarray, lag: int, var: float) -> float:
    """:func:`_unlike` with the total variance of ``X`` given (many lags of one ``X``)."""
    if not var > 0 or not 0 < lag < X.shape[0]:
        return float("nan")
    return float(_lag_steps(X, lag).mean()) / (2.0 * var)


def _lag_steps(X: np.ndarray, lag: int) -> np.ndarray:
    """``(T - lag,)``: the squared distance of each row of ``X`` ``(T, D)`` from the row ``lag`` later."""
    return ((X[lag:] - X[:-lag]) ** 2).sum(axis=1)


def legs_repeat(motion: Motion, start: int, stop: int, period: float) -> float:
    """How unlike the legs are to themselves one ``period`` later over frames ``start .. stop-1`` (see
    :func:`_unlike`; NaN when it cannot be told)."""
    X = _leg_features(motion, start, stop)
    lag = int(round(period)) if np.isfinite(period) else 0
    return float("nan") if X is None else _unlike(X, lag)


def _legs_repeat_in(motion: Motion, part: Activity) -> bool:
    """Whether the legs of a gait part are like themselves one stride later, over the part (and, for a part of
    under two strides, up to a step on either side, then, where that does not show it, up to a stride, so
    that a stride can be compared with the next): unlikeness under :data:`UNLIKE` where a stride or more of
    frames can be compared, under :data:`UNLIKE_ONE_STEP` where less can.  A part of two strides or more is
    judged on its own frames only: in a session the frames beside it are another activity; so is a shorter one
    whose own frames compare a step or more and are alike, a stride later by the landings or by the legs' own
    stride (:func:`short_period`, as :func:`legs_check` finds it; the frames beside it are looked at only where
    its own cannot tell).  A step on either side first: a part's landings may start a step or more into its take
    (a landing lost where the take is joined to the one before), and a stride's reach then takes in the next
    activity, which is unlike the part's legs however alike its own strides are."""
    P = part.period_frames
    if not (np.isfinite(P) and P >= 2):
        return False
    lag = int(round(P))
    if part.n_frames < 2 * lag:
        X = _leg_features(motion, part.start, part.stop)
        if X is not None:
            # one stride later by the landings, or else by the legs' own stride where legs_check looks for it
            # (a few landings of floating feet, measured from their stances' own levels, may make a stride some
            # frames long or short: an iClone jog's 50 frames where its legs repeat at 45)
            if _alike_over_a_step(X, lag):
                return True
            legs, _ = _short_period_of(X, P)
            if np.isfinite(legs) and _alike_over_a_step(X, int(round(legs))):
                return True
    reaches = [0.0] if part.n_frames >= 2 * P else [0.5 * P, P]
    for reach in reaches:
        lo, hi = max(0, int(part.start - reach)), min(motion.n_frames, int(np.ceil(part.stop + reach)))
        X = _leg_features(motion, lo, hi)
        if X is None:
            return True  # no legs to tell by: the landings decide
        overlap = X.shape[0] - lag
        if overlap >= _least_overlap(lag) and _unlike(X, lag) < (UNLIKE if overlap >= lag else UNLIKE_ONE_STEP):
            return True
    return False


def _alike_over_a_step(X: np.ndarray, lag: int) -> bool:
    """Whether the rows of ``X`` ``(T, D)`` are like themselves ``lag`` rows later (:data:`UNLIKE_ONE_STEP`) where
    they compare a step or more but less than a stride (``lag / 2 <= T - lag < lag``)."""
    return lag / 2 <= X.shape[0] - lag < lag and _unlike(X, lag) < UNLIKE_ONE_STEP


#: The legs' self-similar period overrules the landings' when it is this far off and the legs are at least
#: LEGS_BETTER times as unlike at the landings' period as at their own (a landing seen early or late skews a
#: line through a few landings; the legs' repeat is measured on every frame).
LEGS_OVERRULE, LEGS_BETTER = 0.02, 1.5


def legs_check(motion: Motion, start: int, stop: int, period: float, said: str = "the landings'") -> tuple[float, str]:
    """The landings' ``period`` (or another estimate's: ``said`` names it) checked by the legs over frames
    ``start .. stop-1``: ``(NaN, why)`` when the legs agree (or cannot tell), ``(their period, why)`` when they
    are most alike more than :data:`LEGS_OVERRULE` away from it and :data:`LEGS_BETTER` times as alike there (a
    landing detected early or late)."""
    X = _leg_features(motion, start, stop)  # made once for both measures
    legs, unlike = _short_period_of(X, period)
    at = float("nan") if X is None else _unlike(X, int(round(period)) if np.isfinite(period) else 0)
    if not np.isfinite(legs) or abs(legs / period - 1) <= LEGS_OVERRULE:
        return float("nan"), (f"the legs agree ({legs:.2f} frames)" if np.isfinite(legs) else
                              "the legs cannot tell")
    if not (np.isfinite(at) and LEGS_BETTER * unlike < at):
        return float("nan"), f"the legs' {legs:.2f} frames are not clearly better"
    return float(legs), (f"the legs are most alike {legs:.2f} frames apart (unlikeness {unlike:.2f} against "
                         f"{at:.2f} at {said} {period:.2f})")


def stride_reference(motion: Motion, landings: Landings, start: int, stop: int) -> tuple[list[float], int]:
    """The stride periods over frames ``start .. stop`` that a loop may be held to: the median stride of the
    landings there, and the legs' own period when they overrule it (:func:`legs_check`: a landing seen early or
    late); and the number of strides measured (0: no ruler, an empty list)."""
    strides = stride_periods(landings, motion.fps, start, stop)
    if not strides:
        return [], 0
    median = float(np.median(strides))
    legs, _ = legs_check(motion, start, stop, median)
    return [median] + ([legs] if np.isfinite(legs) else []), len(strides)


def short_period(motion: Motion, guess: float, start: int, stop: int) -> tuple[float, float]:
    """The period (frames) of the legs over frames ``start .. stop-1`` of little more than a cycle: the lag within
    ``[0.75, 1.33]`` of ``guess`` at which the legs' rotations are most like themselves
    (:func:`_unlike` over the frames both ends cover, at least a sixth of a period of overlap), refined by a
    parabola.  ``(NaN, value)`` when the best lag is not alike (:data:`UNLIKE` or more) or no lag fits.
    Returns ``(period, unlikeness)``."""
    return _short_period_of(_leg_features(motion, start, stop), guess)


def _short_period_of(X: np.ndarray | None, guess: float) -> tuple[float, float]:
    """:func:`short_period` on the legs' features ``X (T, D)`` (``None``: no legs)."""
    if X is None:
        return float("nan"), float("nan")
    T = X.shape[0]
    lags = np.arange(max(2, int(np.floor(PERIOD_SEARCH[0] * guess))), int(np.ceil(PERIOD_SEARCH[1] * guess)) + 1)
    lags = lags[T - lags >= _least_overlap(lags)]
    if lags.size < 3:
        return float("nan"), float("nan")
    var = float(X.var(axis=0).sum())
    d = np.array([_unlike_var(X, int(lag), var) for lag in lags])
    if not np.isfinite(d).all():
        return float("nan"), float("nan")
    i = int(np.argmin(d))
    best = float(lags[i])
    if 0 < i < d.size - 1:
        den = d[i - 1] - 2 * d[i] + d[i + 1]
        if den > 0:
            best += 0.5 * (d[i - 1] - d[i + 1]) / den
    if not d[i] < UNLIKE:
        return float("nan"), float(d[i])
    return best, float(d[i])


def _reach(motion: Motion, parts: list[Activity], T: int, changes: Collection[int] = ()) -> None:
    """Let each gait part reach up to one step before its first and after its last landing (the take starts or
    ends mid-stride; up to a stride at the take's ends), short of its neighbours and only as far as its legs
    still repeat the stride (:func:`_repeating_reach`: where the gait stops or blends into another motion, the
    part stops); into a gap smaller than a step left after the part before it, a part reaches back as far as its
    legs repeat, and the part before reaches on into what is left as far as its own legs repeat (frames neither
    part's legs repeat through, where one motion blends into the next, are left between them: split in halves,
    they held a third of a stride of another take).  A part that starts or ends at a landing of ``changes``
    (where the gait changes, :func:`_gait_changes`) stays there: the step across the change is a blend of the
    two gaits, neither part's, even where the legs repeat alike on both sides of it."""
    for k, p in enumerate(parts):
        step = p.period_frames / 2.0
        lo = parts[k - 1].stop if k > 0 else 0
        if p.start in changes:
            pass
        elif k > 0 and p.start - lo < step and parts[k - 1].stop not in changes:  # a gap under a step: reach
            p.start = _repeating_reach(motion, p, lo, p.start)  # into it as far as the legs repeat
            if p.start > lo:  # and the part before, as far as its own legs repeat
                parts[k - 1].stop = _repeating_reach(motion, parts[k - 1], p.start, lo)
        else:  # at the take's start a foot may be mid-swing: up to a stride
            want = max(lo, int(np.floor(p.start - (2 * step if k == 0 else step))))
            p.start = _repeating_reach(motion, p, want, p.start)
        if p.stop in changes:
            continue
        if k + 1 == len(parts):
            want = min(T, int(np.ceil(p.stop + 2 * step)))
            p.stop = _repeating_reach(motion, p, want, p.stop)
        elif parts[k + 1].start - p.stop >= step:
            p.stop = _repeating_reach(motion, p, int(np.ceil(p.stop + step)), p.stop)


def _repeating_reach(motion: Motion, part: Activity, want: int, edge: int) -> int:
    """How far towards ``want`` (a frame before the part's first landing or after its last, ``edge``) the
    part's legs still repeat its stride: the first frame from ``edge`` at which the legs are unlike their pose
    a stride before (after, going back) by :data:`UNLIKE` or more (over 3 frames; unlikeness against the
    legs' spread over the stride next to the edge, as :func:`_unlike` measures it) ends the reach."""
    lag = int(round(part.period_frames))
    if want == edge or lag < 2:
        return want
    forward = want > edge
    lo, hi = (edge - lag, want) if forward else (want, edge + lag)
    lo, hi = max(0, lo), min(motion.n_frames, hi)
    X = _leg_features(motion, lo, hi)
    if X is None or X.shape[0] <= lag:
        return want
    ref = X[max(0, edge - lo - lag): edge - lo] if forward else X[edge - lo: edge - lo + lag]
    var = float(ref.var(axis=0).sum()) if ref.shape[0] >= 2 else 0.0  # (a stride before a take's first frames)
    if not var > 0:
        return want
    d = ((X[lag:] - X[:-lag]) ** 2).sum(axis=1) / (2.0 * var)   # frame t + lag against frame t (relative to lo)
    d = moving_average(d, 3)
    if forward:  # frames edge .. want-1 against a stride before (those a stride into the take, near its start)
        first = max(0, edge - lo - lag)
        bad = np.flatnonzero(d[first:] >= UNLIKE)
        return lo + lag + first + int(bad[0]) if bad.size else want
    top = min(edge - lo, d.size)  # frames edge-1 .. want against a stride after, going back (from a stride
    bad = np.flatnonzero(d[:top][::-1] >= UNLIKE)  # before the take's end, near it)
    return lo + top - int(bad[0]) if bad.size else want


def _fill(motion: Motion, parts: list[Activity], landings: Landings, min_periods: float, options: dict,
          map=map) -> list[Activity]:
    """The parts with the frames between them (and before the first, after the last) as parts of their own,
    each stretch looked at on its own (:func:`_other`, through ``map``) with the landings in it."""
    T = motion.n_frames
    gaps, at = [], 0
    for p in [*parts, None]:
        stop = T if p is None else p.start
        if stop > at:
            gaps.append((at, stop))
        if p is not None:
            at = p.stop
    found = map(_gap_parts, [_Gap(motion[a:b], a, min_periods, bool(parts), options, _steps_in(landings, a, b))
                             for a, b in gaps])
    out = [*parts, *(q for qs in found for q in qs)]
    return sorted(out, key=lambda q: q.start)


@dataclass(frozen=True)
class _Gap:
    """Frames between gait parts to look at on their own (sent as they are to another process)."""

    motion: Motion
    offset: int
    min_periods: float
    gait_near: bool
    options: dict
    #: the landings in the stretch, in its frames
    steps: Landings | None = None


def _steps_in(landings: Landings | None, a: int, b: int) -> Landings | None:
    """The landings in frames ``a .. b-1``, in those frames (frame ``a`` first)."""
    if landings is None:
        return None
    inside = (landings.frames >= a) & (landings.frames < b)
    return Landings(landings.frames[inside] - a, landings.foot[inside], landings.sides, landings.down[a:b])


def _foot_periods(steps: Landings | None, start: int, stop: int, fps: float) -> np.ndarray:
    """The strides of ``steps`` over frames ``start .. stop-1``: frames from a landing to the same foot's next
    where the other foot lands once between, each step :data:`MIN_STEP_S` .. :data:`MAX_STEP_S` long (a landing
    missed or a foot that shuffles makes no stride)."""
    if steps is None or steps.frames.size < 3:
        return np.zeros(0)
    f, foot = steps.frames.astype(np.float64), steps.foot
    d1, d2 = f[1:-1] - f[:-2], f[2:] - f[1:-1]
    lo, hi = MIN_STEP_S * fps, MAX_STEP_S * fps
    ok = (foot[:-2] == foot[2:]) & (foot[1:-1] != foot[:-2]) & (d1 >= lo) & (d1 <= hi) & (d2 >= lo) & (d2 <= hi)
    ok &= (f[2:] > start) & (f[:-2] < stop - 1)
    return (f[2:] - f[:-2])[ok]


def _in_step(periods: np.ndarray, period: float) -> bool | None:
    """Whether feet whose strides last ``periods`` frames (:func:`_foot_periods`) step in time with a motion of
    ``period`` frames: their median within :data:`IN_STEP` of it and every one within :data:`TEMPO_CHANGE` (a
    stride blended across a take's border may stray); ``None`` when the feet make no stride."""
    if periods.size == 0:
        return None
    off = np.abs(periods / period - 1.0)
    return bool(abs(float(np.median(periods)) / period - 1.0) <= IN_STEP and np.all(off <= TEMPO_CHANGE))


def _gap_parts(gap: _Gap) -> list[Activity]:
    """:func:`_other` of a stretch between gait parts, in the take's frames (its frames and its landings)."""
    out = _other(gap.motion, 0, gap.motion.n_frames, gap.min_periods, gap.gait_near, gap.options, steps=gap.steps)
    for q in out:
        q.start, q.stop = q.start + gap.offset, q.stop + gap.offset
        q.landings = {side: [f + gap.offset for f in frames] for side, frames in q.landings.items()}
    return out


def _other(motion: Motion, start: int, stop: int, min_periods: float, gait_near: bool, options: dict,
           when: str = "", steps: Landings | None = None) -> list[Activity]:
    """Frames ``start .. stop-1`` without gait: an arms part, a periodic part, a gesture, standing or a short
    transition between gait parts.  What lies before and after a repeating region is looked at again the same
    way (a wave, then a dance step), so that every repeating motion without gait is a part of its own.
    ``when``: ``"before"``/``"after"`` for the frames beside a repeating region.

    ``steps``: the landings in ``motion``.  Where the feet land in the frames, they are evidence of their own: a
    motion whose feet land a period apart (:func:`_in_step`: a gait whose chain of landings broke, a landing
    missed) repeats as surely as a gait, with ``min_periods`` cycles, and is a walk or a run named by its feet
    (:func:`_stepping_part`); one whose legs
    are unlike themselves a period later (:func:`legs_repeat`, :data:`UNLIKE`) while the feet step is no one
    motion (a walk slowing into a run) and is a transition."""
    n = stop - start
    if n < MIN_OTHER_S * motion.fps:
        if when:
            return [Activity(start=start, stop=stop, kind="gesture", limbs="none",
                             reason=f"the movement {when} the repeating part: it happens once")]
        kind = "transition" if gait_near else "gesture"
        why = "between activities" if gait_near else "in the whole take"
        frames = f"{n} frame" if n == 1 else f"{n} frames"
        return [Activity(start=start, stop=stop, kind=kind, limbs="none",
                         reason=f"only {frames} ({n * motion.frame_time:.1f} s) {why}: too short to repeat")]
    piece = motion[start:stop]
    spread = _rotation_spread(piece)
    if float(np.sort(spread)[-min(3, spread.size)]) < STILL_DEG:  # fewer than three joints move
        return [Activity(start=start, stop=stop, kind="standing", limbs="none",
                         reason="the actor stands: nothing moves enough to loop")]
    stepping = _foot_periods(steps, start, stop, motion.fps).size > 0

    def look(fewer: bool):
        """What repeats (:func:`_periodic_in`; ``fewer``: ``min_periods`` cycles may do) and whether the feet land
        in step with it."""
        found = _periodic_in(piece, spread, min_periods, options, fewer)
        if found is not None:  # what repeats must move: noise while the actor stands after a gesture does not
            a, b = found[3]
            if float(_rotation_spread(piece[a:b]).max()) < STILL_DEG:
                return None, None
        if found is None or found[1] != "periodic":
            return found, None
        (s, e), P = found[3], found[2].period_frames
        return found, _in_step(_foot_periods(steps, start + s, start + e, motion.fps), P)

    found, in_step = look(stepping)
    if stepping and found is not None and not in_step and \
            found[3][1] - found[3][0] < max(min_periods, MIN_REPEATS) * found[2].period_frames:
        found, in_step = look(False)  # the feet do not see so few cycles repeat: looked at as if they did not land
    still = _legs_still(piece.skeleton, spread)
    if found is None:
        return [Activity(start=start, stop=stop, kind="gesture", limbs="none", legs_still=still,
                         reason="no repeating motion: the body moves once, it does not repeat")]
    limbs, kind, pm, (s, e) = found
    out = []
    if s > 0:
        out.extend(_other(motion, start, start + s, min_periods, gait_near, options, "before", steps))
    P = pm.period_frames
    # feet that land in it (a stride or only a step or two) say whether the legs come back a period later; so do
    # legs that move where no foot lands (a shuffle's last steps): a whole body that repeats repeats its legs too
    steps_in = kind == "periodic" and steps is not None and \
        bool(np.any((steps.frames >= start + s) & (steps.frames < start + e)))
    legs_move = kind == "periodic" and not _legs_still(piece.skeleton, _rotation_spread(piece[s:e]))
    legs = legs_repeat(motion, start + s, start + e, P) if steps_in or legs_move else float("nan")
    why = f"{kind}: {(e - s) / P:.1f} periods of {P:.1f} frames"
    if np.isfinite(legs) and legs >= UNLIKE:
        said = ("the feet step but the legs are unlike themselves a period ({P:.1f} frames) later: the gait changes "
                "here" if steps_in else "the legs move but are unlike themselves a period ({P:.1f} frames) later: "
                "the body does not repeat at that period")
        out.append(Activity(start=start + s, stop=start + e, kind="transition", limbs="none", legs_still=still,
                            reason=said.format(P=P) + ", no one motion"))
    elif in_step and steps is not None:
        out.append(_stepping_part(motion, start + s, start + e, pm, steps, why))
    else:
        out.append(Activity(start=start + s, stop=start + e, kind=kind, limbs=limbs, period_frames=pm.period_frames,
                            loop=True, periodic=pm, legs_still=still))
    if e < n:
        out.extend(_other(motion, start + e, stop, min_periods, gait_near, options, "after", steps))
    return out


def _stepping_part(motion: Motion, start: int, stop: int, pm: PeriodicMotion, steps: Landings,
                   why: str) -> Activity:
    """Frames ``start .. stop-1`` of ``motion`` where the body repeats every ``pm.period_frames`` and the feet
    (``steps``, in ``motion``'s frames) land in step with it: a gait whose chain of landings broke, named by its
    feet (:func:`gait_of` over its frames) and its turn per cycle (:data:`TURN_DEG`), its phase ``pm``'s, or,
    where its legs overrule that period as they do a gait part's (:func:`legs_check`: over a cycle and a half
    the cohomology's period came out 2-6 % short of the legs' own), a line at the legs' period from ``pm``'s
    first phase."""
    P = pm.period_frames
    legs, check = legs_check(motion, start, stop, P, said="the cohomology's")
    if np.isfinite(legs):
        x = pm.unwrapped[0] + np.arange(stop - start) / legs
        pm = line_periodic(x, legs, motion.frame_time, "legs self-similarity", "legs",
                           f"the legs' self-similarity: {check}")
        why = f"{why}; {check}"
        P = legs
    piece = motion[start:stop]
    down = steps.down[start:stop]
    path = _horizontal_path(piece)
    n = max(stop - start - 1, 1)
    speed = float(np.linalg.norm(path[-1] - path[0])) * motion.fps / n
    heading = heading_degrees(piece)
    turn = float(heading[-1] - heading[0])
    per_cycle = turn * P / n
    gait = gait_of(float(np.mean(down == 0)), float(np.mean(down >= 2)), speed, _body_height(piece))
    way = "straight" if abs(per_cycle) < TURN_DEG else ("turning left" if per_cycle > 0 else "turning right")
    own: dict[str, list[int]] = {}
    inside = (steps.frames >= start) & (steps.frames < stop)
    for f, k in zip(steps.frames[inside].tolist(), steps.foot[inside].tolist(), strict=True):
        own.setdefault(steps.sides[k], []).append(int(f))
    return Activity(start=start, stop=stop, kind=f"{gait} {way}", limbs="legs", period_frames=P, speed=speed,
                    turn_deg=turn, loop=True, periodic=pm, legs_still=False, in_step=True, landings=own,
                    reason=f"{why}, the feet landing a period apart (a gait whose chain of landings broke)")


def _rotation_spread(motion: Motion) -> np.ndarray:
    """Each joint's rotation spread ``(J,)`` in degrees: the RMS angle of its rotations from their mean."""
    return _spread_of(motion.rotations)


def _spread_of(q: np.ndarray) -> np.ndarray:
    """:func:`_rotation_spread` of quaternions ``q (T, J, 4)``."""
    mean = mean_rotations(q)
    ang = quat_angles(q, np.broadcast_to(mean, q.shape))
    return np.degrees(np.sqrt(np.mean(ang ** 2, axis=0)))


def _legs_stand(motion: Motion, start: int, stop: int) -> bool:
    """:func:`_legs_still` over frames ``start .. stop-1``, the spread measured on the leg joints only."""
    legs = _leg_joint_indices(motion.skeleton)
    return _still_legs(_spread_of(motion.rotations[start:stop, legs]) if legs else np.zeros(0))


def _moving_arm_joints(skeleton, spread: np.ndarray) -> list[str]:
    """The arm joints that move (spread at least :data:`MOVING_SHARE` of the most moving arm joint's)."""
    try:
        arms = skeleton.select("arms")
    except MocycleError:
        return []
    top = float(spread[arms].max()) if arms else 0.0
    if top < STILL_DEG:
        return []
    return [skeleton.names[j] for j in arms if spread[j] >= MOVING_SHARE * top]


def _legs_still(skeleton, spread: np.ndarray) -> bool:
    """Whether the legs stand: no leg joint's rotation spreads (``spread``, every joint's) more than twice
    :data:`STILL_DEG`."""
    return _still_legs(spread[_leg_joint_indices(skeleton)])


def _leg_joint_indices(skeleton) -> list[int]:
    """The rig's leg joints (none when it names none)."""
    try:
        return skeleton.select("legs")
    except MocycleError:
        return []


def _still_legs(leg_spread: np.ndarray) -> bool:
    """:func:`_legs_still` of the leg joints' spread ``(L,)`` (degrees): no legs stand too."""
    return leg_spread.size == 0 or float(leg_spread.max()) < 2 * STILL_DEG


def _repeating_region(piece: Motion, joints, least: float) -> tuple[int, int, float] | None:
    """Where ``joints`` repeat in ``piece``: ``(start, stop, period)`` from the velocity of their rotations
    (a wave's hand swings back and forth while the arm's raise and fall happen once): the period by windowed
    autocorrelation (paper 004), the frames where the take is like itself one period later
    (:func:`~mocycle.phase.period.repetition_distance` under a half) and comes back to its poses
    (:func:`_return_distance`) and moves (at least a fifth of the largest local speed among those frames: a big
    gesture beside a small wave does not hide it), their longest run.  A motion repeats at twice its period
    too, so where the run's own frames of named ``joints`` (an arm) repeat at a shorter period than the
    piece's (a quick wave beside a slow one), that period and its run are taken (up to :data:`PERIOD_REFINES`
    times; the whole body's period is the cohomology's to check).  ``None`` when it holds fewer than
    ``least`` periods."""

    X, _ = pose_matrix(piece, rep="expmap", root_features="drop", joints=joints, normalize=False, weights=None)
    V = np.diff(X, axis=0)
    min_lag = max(2, int(round(MIN_REPEAT_S * piece.fps)))
    if V.shape[0] < 2 * min_lag + 2:
        return None
    P = autocorrelation_period(V, min_lag=min_lag)
    found = _run_at(X, V, P)
    for _ in range(PERIOD_REFINES if joints is not None else 0):
        if found is None:
            break
        s, e = found
        if e - s - 1 < 2 * min_lag + 2:
            break
        own = autocorrelation_period(V[s:e - 1], min_lag=min_lag)
        if not (np.isfinite(own) and own < (1.0 - PERIOD_AGREEMENT) * P):
            break
        shorter = _run_at(X, V, own)
        if shorter is None or (shorter[1] - shorter[0]) < least * own:
            break
        found, P = shorter, own
    if found is None or (found[1] - found[0]) < least * P:
        return None
    return found[0], found[1], float(P)


def _run_at(X: np.ndarray, V: np.ndarray, P: float) -> tuple[int, int] | None:
    """The longest run of frames where poses ``X`` ``(T, D)`` (velocities ``V`` ``(T-1, D)``) repeat at period
    ``P`` and move (:func:`_repeating_region`), as ``(start, stop)``; ``None`` where none do."""
    if not np.isfinite(P):
        return None
    w = max(3, int(round(P)))
    alike = (repetition_distance(V, P, smooth=w) < ALIKE) & (_return_distance(X[1:], P, w) < ALIKE)
    if not alike.any():
        return None
    energy = moving_average((V ** 2).sum(axis=1), w)
    busy = energy > BUSY_SHARE * energy[alike].max()
    runs = _true_runs(alike & busy)
    if not runs:
        return None
    s, e = max(runs, key=lambda r: r[1] - r[0])
    return s, min(X.shape[0], e + 1)  # velocities: frame e + 1 ends the last one (the smoothing reaches w/2 out)


def _return_distance(X: np.ndarray, period: float, w: int) -> np.ndarray:
    """Per frame, how far poses ``X`` ``(T, D)`` are from coming back one ``period`` later (or earlier): the
    squared step ``||x(t + P) - x(t)||²`` against the poses' own spread over a period about ``t`` (twice their
    variance over ``w`` frames), the nearer side, averaged over ``w`` frames: about 0 where the motion comes
    back to its pose (a wave's swings), 6 or more where it moves on at an even pace (an arm raised slowly,
    whose velocity is alike a period later although nothing repeats).  ``(T,)``."""
    T = X.shape[0]
    P = int(round(period))
    if T < 2 or P < 1 or P >= T:
        return np.zeros(T)
    mean = np.stack([moving_average(X[:, d], w) for d in range(X.shape[1])], axis=1)
    square = np.stack([moving_average(X[:, d] ** 2, w) for d in range(X.shape[1])], axis=1)
    spread = np.maximum((square - mean ** 2).sum(axis=1), 1e-12)
    step = _lag_steps(X, P)
    # a frame with no pose a period away on either side (a period over half the frames) cannot be seen to come
    # back: far from alike, and finite, so that the running mean stays a number
    d = np.full((2, T), 2.0 * w / ALIKE)
    d[0, :-P] = step / (2.0 * spread[:-P])
    d[1, P:] = step / (2.0 * spread[P:])
    return moving_average(d.min(axis=0), w)


def _true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def _periodic_in(piece: Motion, spread: np.ndarray, min_periods: float, options: dict, stepping: bool = False):
    """``(limbs, kind, PeriodicMotion, (start, stop))`` of the motion repeating in ``piece`` (frames of the
    piece; the PeriodicMotion is on those frames): the arm joints that move and the whole body, the arms first
    where the legs stand (a wave), the body first where they move (a dance step; the arms then, for a wave
    among other movements), or the joints of ``options["joints"]``; ``None`` when nothing repeats.
    ``options``: :func:`~mocycle.phase.find_phase`'s, and ``step``.  ``stepping``: the feet land in the piece,
    so a region of ``min_periods`` is looked at (the landings then say whether it repeats, :func:`_other`)."""
    options = dict(options)
    step = _phase_step_in(options.pop("step", None), piece.fps, stepping)
    chosen = options.pop("joints", None)
    if chosen is not None:
        tries = [(chosen, "periodic")]
    else:  # the arms first where the legs stand (a wave), the whole body first where they move (a dance)
        moving = _moving_arm_joints(piece.skeleton, spread)
        arms = [(moving, "arms")] if moving else []
        tries = arms + [(None, "periodic")] if _legs_still(piece.skeleton, spread) else [(None, "periodic")] + arms
    least = min_periods if stepping else max(min_periods, MIN_REPEATS)
    for joints, kind in tries:
        region = _repeating_region(piece, joints, least)
        if region is None:
            if joints is not None and chosen is None:
                continue
            region = (0, piece.n_frames, float("nan"))  # the cohomology finds where it repeats
        s, e, acf = region
        sub = piece[s:e]
        limbs = joints if isinstance(joints, str) else ",".join(joints) if joints else "all"
        try:
            result = find_phase_every(sub, step, joints=joints, min_periods=least, **options)
            classes = result.classes
        except (NoPeriodicMotion, MocycleError):
            classes = []
        longest = MAX_REPEAT_S * piece.fps
        agree = [c for c in classes if (not np.isfinite(acf) or abs(c.period_frames / acf - 1) <= 2 * PERIOD_AGREEMENT)
                 and c.period_frames <= longest]
        if agree:
            pm = max(agree, key=lambda c: len(c.frames()))
            a, b = pm.excitation[0][0], pm.excitation[-1][1]
            return limbs, kind, _rebased(pm, a, b), (s + a, s + b)
        if not np.isfinite(acf) or joints is None or acf > longest:
            continue  # the whole body needs the cohomology's word; an arm that swings on its own, the autocorrelation's
        x = np.arange(e - s, dtype=np.float64) / acf
        why = (f"the autocorrelation of the {'moving arm joints' if kind == 'arms' else 'joints'}' velocities: "
               f"{acf:.2f} frames" + (f" (the cohomology's {', '.join(f'{c.period_frames:.2f}' for c in classes)} "
                                      f"disagree)" if classes else " (the cohomology found no class)"))
        return limbs, kind, line_periodic(x, acf, piece.frame_time, "autocorrelation", limbs, why), (s, e)
    return None


def _rebased(pm, a: int, b: int):
    """``pm`` on its frames ``a .. b-1`` only (frame ``a`` first)."""

    regions = [(max(s, a) - a, min(e, b) - a) for s, e in pm.excitation if min(e, b) > max(s, a)]
    return replace(pm, coords=pm.coords[a:b], unwrapped=pm.unwrapped[a:b], excitation=regions)


def line_periodic(x: np.ndarray, period: float, frame_time: float, source: str, joints_used: str, reason: str):
    """A :class:`~mocycle.phase.analysis.PeriodicMotion` whose time is ``x`` ``(n,)`` (cycles; a line: one
    tempo) over all its frames, with the period estimator that made it named."""

    x = np.asarray(x, dtype=np.float64)
    n = x.size
    return PeriodicMotion(birth=float("nan"), death=float("nan"), coords=np.mod(x, 1.0), unwrapped=x - np.floor(x[0]),
                          excitation=[(0, n)], period_frames=float(period), n_periods=float(n / period),
                          frame_time=frame_time, joints_used=joints_used, period_source=source,
                          period_candidates={source: float(period)}, period_reason=reason)


# ------------------------------------------------------------------------------------------- stride phase
def stride_phase(part: Activity, landings_frames: np.ndarray, landings_foot: np.ndarray, start: int,
                 stop: int) -> tuple[np.ndarray, float]:
    """Time in cycles ``(stop - start,)`` through the landings (take frames) that fall within a step of
    ``[start, stop)``, alternate feet and step within :data:`STEP_RATIO` of their median step (their longest
    such run in the part): a least-squares line
    ``t = t0 + P (k/2) + c [foot is the second one]`` over the
    landings' step counts ``k``, so each foot's landings are a whole cycle ``P`` apart.  Returns the time
    (cycles, frame ``start`` first) and ``P`` (frames)."""
    step = part.period_frames / 2.0 if np.isfinite(part.period_frames) else 0.0
    near = (landings_frames >= start - step) & (landings_frames <= stop + step)
    f = landings_frames[near].astype(np.float64)
    foot = landings_foot[near]
    if f.size >= 2:  # the run of landings that alternate feet with steps of a like length holding most of the
        # part (another gait's landings nearby, or a step across a join or a missed landing, do not bend the line)
        steps = np.diff(f)
        typical = float(np.median(steps))
        ratio = steps / typical if typical > 0 else np.ones_like(steps)  # (landings on one frame: no step to tell)
        cuts = np.flatnonzero((foot[1:] == foot[:-1]) | (ratio > STEP_RATIO) | (ratio < 1.0 / STEP_RATIO)) + 1
        runs = np.split(np.arange(f.size), cuts)
        best = max(runs, key=lambda r: (np.count_nonzero((f[r] >= start) & (f[r] < stop)), r.size))
        f, foot = f[best], foot[best]
        # a landing outside the part only carries its phase to the part's edge when it steps at the part's tempo
        # (within TEMPO_CHANGE of its median step): the first step into the next take is often a blend, long
        # enough to pass STEP_RATIO and bend the line (a 30 fps run at 22.3 frames where its feet land every 21)
        if f.size >= 4:
            run_step = float(np.median(np.diff(f)))  # this run's median step, not all the landings'
            lo, hi = 0, f.size
            if f[0] < start and abs((f[1] - f[0]) / run_step - 1.0) > TEMPO_CHANGE:
                lo = 1
            if f[-1] >= stop and abs((f[-1] - f[-2]) / run_step - 1.0) > TEMPO_CHANGE and hi - lo > 3:
                hi -= 1
            f, foot = f[lo:hi], foot[lo:hi]
    if f.size < 3:
        raise MocycleError(f"a stride phase needs three landings; frames {start}-{stop} have {f.size}")
    k = np.arange(f.size, dtype=np.float64)
    second = (foot != foot[0]).astype(np.float64)
    B = np.column_stack([np.ones_like(k), k / 2.0, second])
    (t0, P, _), *_ = np.linalg.lstsq(B, f, rcond=None)
    if not P >= 2.0:  # (landings on one frame or going back: no stride)
        raise MocycleError(f"the landings of frames {start}-{stop} give no stride period")
    t = np.arange(start, stop, dtype=np.float64)
    return (t - t0) / P, float(P)


# ------------------------------------------------------------------------------------------- what to say
def nothing_to_loop(acts: Activities) -> str:
    """Why nothing in the take loops, in plain words."""
    if not acts.parts:
        return "no repeating motion found in the take"
    if len(acts.parts) == 1 and acts.parts[0].n_frames * acts.frame_time < MIN_OTHER_S:
        return acts.parts[0].reason  # a take too short to be looked at: its part says so
    kinds = {p.kind for p in acts.parts}
    if kinds == {"standing"}:
        return "no repeating motion: the actor stands still"
    gait = [p for p in acts.parts if p.gait or p.landings]
    if gait and not any(p.loop for p in acts.parts):
        longest = max(gait, key=lambda p: p.n_periods if np.isfinite(p.n_periods) else 0.0)
        return (f"no steady part repeats long enough to loop: the longest ({longest.kind or 'steps'}, frames "
                f"{longest.start}-{longest.stop}) holds {longest.n_periods:.1f} strides")
    if kinds <= {"gesture", "standing", "transition"}:
        return "no repeating motion: the take does one gesture, it does not repeat"
    return "no repeating motion found: the body moves, but nothing in it repeats"


def parts_phase(acts: Activities) -> PhaseResult:
    """The take's periodic motions as ``mocycle phase`` reports them: one per part that loops, its phase on the
    take's frames (NaN outside the part) and its excitation in take frames: the same parts ``mocycle loop``
    loops."""
    T = acts.n_frames
    classes: list[PeriodicMotion] = []
    for p in acts.loopable():
        pm = p.periodic
        assert pm is not None  # a part loops only with its phase found (_decide, _other, _or_one_cycle)
        coords, unwrapped = np.full(T, np.nan), np.full(T, np.nan)
        coords[p.start:p.stop], unwrapped[p.start:p.stop] = pm.coords, pm.unwrapped
        classes.append(replace(pm, coords=coords, unwrapped=unwrapped,
                               excitation=[(s + p.start, e + p.start) for s, e in pm.excitation],
                               n_periods=float(p.n_periods)))
    reason = _listing(acts.parts) if classes else nothing_to_loop(acts)
    legs = [c.legs_period_frames for c in classes if np.isfinite(c.legs_period_frames)]
    return PhaseResult(classes=classes, barcode=np.zeros((0, 2)), reason=reason,
                       autocorrelation_period_frames=float("nan"), n_frames=T, frame_time=acts.frame_time,
                       joints_used=", ".join(dict.fromkeys(c.joints_used for c in classes)) or "none",
                       legs_period_frames=legs[0] if legs else float("nan"))
