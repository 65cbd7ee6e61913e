"""Steady activities of a take: where it walks straight, turns, runs, waves or stands, before anything is looped.

A take that changes what it does (walk, turn, walk; walk then wave) has no one cycle: a loop fitted over all
of it averages the parts into a motion the actor never made.  :func:`segment_activities` cuts the take into
parts that each do one thing, from evidence that does not depend on the phase:

1. **Foot landings** (:func:`~mocycle.contacts.detect_contacts`): a landing is the start of a foot's contact.
   Landings that alternate between the feet, each step between :data:`MIN_STEP_S` and :data:`MAX_STEP_S`
   seconds, are *gait*; the frames between a foot's landing and its next landing are one **stride**, the
   gait's full cycle (two steps) measured without any phase.
2. **Each stride's figures**: its period (frames), its turn (the hips' heading, :class:`~mocycle.features.
   HeadingFrame`, one stride apart: at the same point of the gait, so the hips' sway within a stride cancels),
   its speed (the travel joint's horizontal distance over its time) and its flight (the share of its frames
   with no foot on the floor: a run has some, a walk none).
3. **Steps of one kind** make a part: each step (half a stride) is *straight* or *turning left/right* (its
   strides turn by more than :data:`TURN_DEG` degrees) and *walk* or *run*; consecutive steps of the same kind
   whose stride periods agree within :data:`TEMPO_CHANGE` are one part.  A part's first and last frames reach
   at most one step beyond its first and last landing (the take starts or ends mid-stride).
4. **The frames between gait parts** (the legs stand, or move without alternating landings) are looked at
   limb by limb: the arm joints that move are tried for a periodic motion first (a wave), then the whole body
   (:func:`~mocycle.phase.find_phase`); what holds no repeating motion is a **gesture** (the body moves) or
   **standing** (it barely does), never looped.

A part is worth a loop when it holds at least ``min_periods`` cycles.  Gait parts carry their **stride
phase** (:func:`stride_phase`): time in cycles through a line fitted to the landings, the period estimator
that still works on a part of 1.2 cycles where the circular coordinate winds about once.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .axes import vertical_axis
from .contacts import body_height, find_feet, up_axis
from .contacts.detect import heights_and_speeds, local_floor
from .contacts.feet import chain_joints, chain_positions
from .errors import MocycleError, NoPeriodicMotion
from .features import HeadingFrame, pose_matrix
from .motion import Motion
from .phase import find_phase
from .phase.analysis import PERIOD_AGREEMENT, PeriodicMotion
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
#: A stride turning by more than this many degrees is a turning stride.
TURN_DEG = 15.0
#: Consecutive strides whose periods differ by more than this share are different activities.
TEMPO_CHANGE = 0.2
#: Faster than this many body heights per second is a run (people switch from walking to running at about
#: 2 m/s, 1.1-1.2 body heights per second).
RUN_SPEED = 1.25
#: Frames without gait shorter than this many seconds are transitions, not looked at for another motion.
MIN_OTHER_S = 1.0
#: A joint of an arm moves when its rotation's spread is at least this share of the most moving arm joint's.
MOVING_SHARE = 0.25
#: The body stands when its joints' mean rotation spread is under this many degrees.
STILL_DEG = 4.0


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
    periodic: object = field(default=None, repr=False)

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


#: A foot is lifted above this height over its floor (body heights), and has landed below LAND_HEIGHT.
LIFT_HEIGHT, LAND_HEIGHT = 0.04, 0.02


def find_landings(motion: Motion) -> Landings | None:
    """The landings of ``motion``'s feet (``None`` when the rig's feet are not found by name).

    A landing is where a foot that was lifted (its lower contact joint, ankle or toe, more than
    :data:`LIFT_HEIGHT` of the body height above its floor) comes down (under :data:`LAND_HEIGHT`).  Heights
    only, no speeds: a foot that glides on the floor (a retargeted or synthetic take, a fitted loop) still
    lands where it comes down, and feet that stay down while the legs sway make no landing.  The floor of
    each joint is its lowest level nearby (:func:`~mocycle.contacts.detect.local_floor`)."""

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
    frames, foot = [], []
    down = np.zeros(motion.n_frames, dtype=np.int8)
    col = 0
    for f, ft in enumerate(feet):
        n = len(ft.contact_joints)
        low = h[:, col:col + n].min(axis=1)
        col += n
        down += low < LAND_HEIGHT
        lifted = False
        for t, v in enumerate(low.tolist()):
            if v > LIFT_HEIGHT:
                lifted = True
            elif lifted and v < LAND_HEIGHT:
                frames.append(t)
                foot.append(f)
                lifted = False
    order = np.argsort(frames, kind="stable")
    return Landings(np.asarray(frames, dtype=np.intp)[order], np.asarray(foot, dtype=np.intp)[order],
                    tuple(f.side for f in feet), down)


def _gait_chains(landings: Landings, fps: float, least: int = 3) -> list[np.ndarray]:
    """Runs of landing indices that alternate feet with steps of plausible length (at least ``least``
    landings; 3: one whole stride)."""
    lo, hi = MIN_STEP_S * fps, MAX_STEP_S * fps
    chains, run = [], [0] if landings.frames.size else []
    for i in range(1, landings.frames.size):
        step = landings.frames[i] - landings.frames[i - 1]
        before = landings.frames[i - 1] - landings.frames[run[-2]] if len(run) >= 2 else step
        if landings.foot[i] != landings.foot[i - 1] and lo <= step <= hi and \
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
    out = []
    for chain in _gait_chains(landings, fps):
        f = landings.frames[chain]
        f = f[(f >= start) & (f <= (stop if stop is not None else f.max()))]
        out.extend(int(f[k + 2] - f[k]) for k in range(f.size - 2))
    return out


# ------------------------------------------------------------------------------------------- segmentation
def heading_degrees(motion: Motion) -> np.ndarray:
    """The hips' (travel joint's) heading ``(T,)`` in degrees, unwrapped, positive turning left about up."""

    frame = HeadingFrame.fit(motion)
    _, psi = frame.tilt(motion)
    # heading_angles runs from e1 towards e2 = up x e1: counter-clockwise seen from above, i.e. to the left
    return np.degrees(np.asarray(psi, dtype=np.float64))


def _body_height(motion: Motion) -> float:

    return float(body_height(motion, up_axis(motion)))


def _horizontal_path(motion: Motion) -> np.ndarray:
    """The travel joint's world position ``(T, 3)`` with its vertical component removed."""

    up = vertical_axis(motion)
    p = motion.joint_path(motion.travel_joint)
    return p - np.outer(p @ up, up)


def _stride_figures(chain, landings, heading, path, fps):
    """Per stride of a chain (landing k to landing k+2, the same foot): period (frames), turn (deg), speed
    (units/s)."""
    f = landings.frames[chain]
    out = []
    for k in range(f.size - 2):
        a, b = int(f[k]), int(f[k + 2])
        speed = float(np.linalg.norm(path[b] - path[a])) * fps / (b - a)
        out.append((float(b - a), float(heading[b] - heading[a]), speed))
    return np.asarray(out)


def _step_kinds(strides: np.ndarray, body: float) -> list[tuple[str, float]]:
    """Each step's kind and stride period: step i lies in strides i-1 and i (those that exist).

    A step turns when its strides turn by more than :data:`TURN_DEG` (the core of a turn), or by more than
    :data:`TURN_EDGE_DEG` the same way next to such steps (a turn's gentle start and end); a straight walk's
    steps stay under both (on the shared walks 95 % under 6 degrees, all under 11)."""
    n_steps = strides.shape[0] + 1
    turns, periods, gaits = [], [], []
    for i in range(n_steps):
        rows = strides[max(0, i - 1): i + 1]
        periods.append(float(rows[:, 0].mean()))
        turns.append(float(rows[:, 1].mean()))
        gaits.append("run" if rows[:, 2].mean() > RUN_SPEED * body else "walk")
    way = [0 if abs(t) <= TURN_DEG else int(np.sign(t)) for t in turns]
    grown = True
    while grown:  # a turn's edges: neighbours turning the same way by more than TURN_EDGE_DEG
        grown = False
        for i in range(n_steps):
            if way[i] == 0 and abs(turns[i]) > TURN_EDGE_DEG:
                sign = int(np.sign(turns[i]))
                if (i > 0 and way[i - 1] == sign) or (i + 1 < n_steps and way[i + 1] == sign):
                    way[i], grown = sign, True
    names = {0: "straight", 1: "turning left", -1: "turning right"}
    return [(f"{g} {names[w]}", p) for g, w, p in zip(gaits, way, periods, strict=True)]


def segment_activities(motion: Motion, *, min_periods: float = 1.2) -> Activities:
    """Cut ``motion`` into steady parts (module notes); ``min_periods``: cycles a part needs to be looped.

    Without feet found by name the whole take is one part of kind ``"periodic"`` on every joint (the phase
    decides).

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> acts = segment_activities(synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion)
    >>> [(p.kind, p.start, p.stop, round(p.period_frames)) for p in acts.parts]
    [('walk straight', 0, 300, 60)]
    """
    T, fps = motion.n_frames, motion.fps
    landings = find_landings(motion)
    if landings is None:
        whole = Activity(start=0, stop=T, kind="periodic", limbs="all", loop=True,
                         reason="the rig's feet were not found by name: the whole take is one part")
        return Activities(parts=[whole], n_frames=T, frame_time=motion.frame_time, feet=False, reason=whole.reason)
    heading = heading_degrees(motion)
    path = _horizontal_path(motion)
    body = _body_height(motion)
    parts: list[Activity] = []
    for chain in _gait_chains(landings, fps, least=2):
        a, b = int(landings.frames[chain[0]]), int(landings.frames[chain[-1]])
        if _legs_still(motion.skeleton, _rotation_spread(motion[a:b + 1])):
            continue  # contacts that flicker while the legs stand are no steps
        if chain.size == 2:  # one step: a take (or a part) of little more than a stride
            short = _one_step_part(motion, chain, landings, heading, path, body)
            if short is not None:
                parts.append(short)
            continue
        strides = _stride_figures(chain, landings, heading, path, fps)
        kinds = _step_kinds(strides, body)
        f = landings.frames[chain]
        i = 0
        while i < len(kinds):
            j = i + 1
            while j < len(kinds) and kinds[j][0] == kinds[i][0] and \
                    abs(kinds[j][1] / kinds[j - 1][1] - 1) <= TEMPO_CHANGE:
                j += 1
            # steps i .. j-1: landings f[i] .. f[j]
            parts.append(_gait_part(kinds[i][0], f, chain, i, j, landings, strides, heading, path, fps))
            i = j
    # steps that land in turn but whose legs do not repeat a stride later (a wander, a stumble) are no gait
    parts = [p for p in parts if _legs_repeat_in(motion, p)]
    parts.sort(key=lambda p: p.start)
    _reach(parts, landings, T)
    _turn_borders(parts, heading)
    parts = _fill(motion, parts, landings, min_periods)
    for p in parts:
        if p.gait:
            p.loop = bool(p.n_periods >= min_periods)
            if p.loop and sum(map(len, p.landings.values())) < 3:  # one step: the legs' self-similarity
                x = (np.arange(p.start, p.stop) - p.start) / p.period_frames
                p.periodic = line_periodic(x, p.period_frames, motion.frame_time, "legs self-similarity", "legs",
                                           f"the legs' self-similarity: the take holds one step, its legs are "
                                           f"most alike {p.period_frames:.2f} frames apart")
            elif p.loop:
                x, period = stride_phase(p, landings.frames, landings.foot, p.start, p.stop)
                legs, why = legs_check(motion, p.start, p.stop, period)
                n = sum(map(len, p.landings.values()))
                if np.isfinite(legs):  # a landing seen early or late: the legs' own repeat decides the period
                    x = (x - x[0]) * period / legs + x[0]
                    p.periodic = line_periodic(x, legs, motion.frame_time, "legs self-similarity", "legs",
                                               f"the legs' self-similarity: {why} (the {n} landings said "
                                               f"{period:.2f})")
                    p.period_frames = legs
                else:
                    p.periodic = line_periodic(x, period, motion.frame_time, "strides", "legs",
                                               f"the strides: landings of each foot {period:.2f} frames apart "
                                               f"(a line through {n} landings; {why})")
                    p.period_frames = period
            else:
                p.reason = (f"{p.kind} for only {p.n_periods:.1f} stride(s): too short for a loop "
                            f"(at least {min_periods:g} wanted)")
                p.kind = "transition" if len(parts) > 1 else p.kind
    kinds = ", ".join(f"{p.kind} {p.start}-{p.stop}" for p in parts)
    return Activities(parts=parts, n_frames=T, frame_time=motion.frame_time, feet=True,
                      reason=f"{len(parts)} part(s): {kinds}" if parts else "no part")


def _gait_part(kind, f, chain, i, j, landings, strides, heading, path, fps) -> Activity:
    a, b = int(f[i]), int(f[j])
    rows = strides[max(0, i - 1): j]  # the strides that overlap steps i .. j-1
    period = float(np.median(rows[:, 0]))
    own = {}
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
    gait = "run" if speed > RUN_SPEED * body else "walk"
    own = {}
    for k in chain:
        own.setdefault(landings.sides[landings.foot[k]], []).append(int(landings.frames[k]))
    return Activity(start=a, stop=b, kind=f"{gait} {way}", limbs="legs", period_frames=period, speed=speed,
                    turn_deg=turn, landings=own,
                    periodic=None, reason=f"one step: the period from the legs' self-similarity ({unlike:.2f})")


def _leg_features(motion: Motion, start: int, stop: int) -> np.ndarray | None:
    """The legs' rotation vectors ``(stop - start, D)`` (no root, not normalised), ``None`` without legs."""

    try:
        X, _ = pose_matrix(motion[start:stop], rep="expmap", root="drop", joints="legs", normalize=False,
                           weights=None)
    except MocycleError:
        return None
    return X


def _unlike(X: np.ndarray, lag: int) -> float:
    """Mean squared difference of the rows of ``X`` ``lag`` apart over twice its total variance: about 0 where
    the motion repeats at that lag, about 1 or more where it does not."""
    var = float(X.var(axis=0).sum())
    if not var > 0 or not 0 < lag < X.shape[0]:
        return float("nan")
    return float(((X[lag:] - X[:-lag]) ** 2).sum(axis=1).mean()) / (2.0 * var)


def legs_repeat(motion: Motion, start: int, stop: int, period: float) -> float:
    """How unlike the legs are to themselves one ``period`` later over frames ``start .. stop-1`` (see
    :func:`_unlike`; NaN when it cannot be told)."""
    X = _leg_features(motion, start, stop)
    lag = int(round(period)) if np.isfinite(period) else 0
    return float("nan") if X is None else _unlike(X, lag)


def _legs_repeat_in(motion: Motion, part: Activity) -> bool:
    """Whether the legs of a gait part are like themselves one stride later, over the part and up to a stride
    on either side: unlikeness under :data:`UNLIKE` where a stride or more of frames can be compared, under
    :data:`UNLIKE_ONE_STEP` where less can."""
    P = part.period_frames
    if not (np.isfinite(P) and P >= 2):
        return False
    lag = int(round(P))
    lo, hi = max(0, int(part.start - P)), min(motion.n_frames, int(np.ceil(part.stop + P)))
    X = _leg_features(motion, lo, hi)
    if X is None:
        return True  # no legs to tell by: the landings decide
    overlap = X.shape[0] - lag
    if overlap < max(4, lag / 6.0):
        return False
    return _unlike(X, lag) < (UNLIKE if overlap >= lag else UNLIKE_ONE_STEP)


#: The legs' self-similar period overrules the landings' when it is this far off and at least twice as alike.
LEGS_OVERRULE = 0.05


def legs_check(motion: Motion, start: int, stop: int, period: float) -> tuple[float, str]:
    """The landings' ``period`` checked by the legs over frames ``start .. stop-1``: ``(NaN, why)`` when the
    legs agree (or cannot tell), ``(their period, why)`` when they are most alike more than
    :data:`LEGS_OVERRULE` away from it and at least twice as alike there (a landing detected early or late)."""
    legs, unlike = short_period(motion, period, start, stop)
    at = legs_repeat(motion, start, stop, period)
    if not np.isfinite(legs) or abs(legs / period - 1) <= LEGS_OVERRULE:
        return float("nan"), (f"the legs agree ({legs:.2f} frames)" if np.isfinite(legs) else
                              "the legs cannot tell")
    if not (np.isfinite(at) and unlike < 0.5 * at):
        return float("nan"), f"the legs' {legs:.2f} frames are not clearly better"
    return float(legs), (f"the legs are most alike {legs:.2f} frames apart (unlikeness {unlike:.2f} against "
                         f"{at:.2f} at the landings' {period:.2f})")


def stride_reference(motion: Motion, landings: Landings, start: int, stop: int) -> tuple[float, int]:
    """The stride period over frames ``start .. stop`` that a loop is checked against: the median stride of the
    landings there, or the legs' own when they overrule it (:func:`legs_check`); and the number of strides
    measured (0: NaN, no ruler)."""
    strides = stride_periods(landings, motion.fps, start, stop)
    if not strides:
        return float("nan"), 0
    median = float(np.median(strides))
    legs, _ = legs_check(motion, start, stop, median)
    return (legs if np.isfinite(legs) else median), len(strides)


def short_period(motion: Motion, guess: float, start: int, stop: int) -> tuple[float, float]:
    """The period (frames) of the legs over frames ``start .. stop-1`` of little more than a cycle: the lag within
    ``[0.75, 1.33]`` of ``guess`` at which the legs' rotations are most like themselves
    (:func:`_unlike` over the frames both ends cover, at least a sixth of a period of overlap), refined by a
    parabola.  ``(NaN, value)`` when the best lag is not alike (:data:`UNLIKE` or more) or no lag fits.
    Returns ``(period, unlikeness)``."""
    X = _leg_features(motion, start, stop)
    if X is None:
        return float("nan"), float("nan")
    T = X.shape[0]
    lags = np.arange(max(2, int(np.floor(0.75 * guess))), int(np.ceil(1.33 * guess)) + 1)
    lags = lags[T - lags >= np.maximum(4, lags / 6.0)]
    if lags.size < 3:
        return float("nan"), float("nan")
    d = np.array([_unlike(X, int(lag)) for lag in lags])
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


def _turn_borders(parts: list[Activity], heading: np.ndarray) -> None:
    """Move each border between a straight and a turning part of one gait to where the turn is half made: the
    frame nearest the landing (within a stride) where the hips' turn over the stride centred on it crosses half
    the turning part's largest.  A step is judged by the strides it lies in, which reach half a stride
    beyond it, so a turning part found from its steps starts and ends about half a stride early and late; the
    turn's half-way rate is where it begins and ends as a viewer sees it."""
    T = heading.size
    for a, b in zip(parts, parts[1:], strict=False):
        if a.stop != b.start or not (a.gait and b.gait) or a.kind.split()[0] != b.kind.split()[0]:
            continue
        turning = [p for p in (a, b) if "turning" in p.kind]
        if len(turning) != 1:
            continue
        turn = turning[0]
        P = int(round(turn.period_frames))
        half = P // 2
        if P < 4 or turn.n_frames <= P:
            continue
        t = np.arange(half, T - half)
        rate = np.full(T, np.nan)
        rate[t] = heading[t + half] - heading[t - half]           # degrees per stride, centred on each frame
        inside = np.abs(rate[turn.start:turn.stop])
        if not np.isfinite(inside).any():
            continue
        level = 0.5 * np.nanmax(inside)
        lo, hi = max(a.start + 1, b.start - P), min(b.stop - 1, b.start + P)
        window = np.abs(rate[lo:hi + 1])
        turning_side = window >= level
        if not np.isfinite(window).all() or turning_side.all() or not turning_side.any():
            continue
        # the crossing nearest the landing, on the side of the straight part
        flips = np.flatnonzero(turning_side[1:] != turning_side[:-1]) + lo + 1
        border = int(flips[np.argmin(np.abs(flips - b.start))])
        if a.start < border < b.stop and min(border - a.start, b.stop - border) >= half:
            a.stop = b.start = border


def _reach(parts: list[Activity], landings: Landings, T: int) -> None:
    """Let each gait part reach up to one step before its first and after its last landing (the take starts or
    ends mid-stride), short of its neighbours; a gap smaller than a step between two parts is split."""
    for k, p in enumerate(parts):
        step = p.period_frames / 2.0
        lo = parts[k - 1].stop if k > 0 else 0
        if k > 0 and p.start - lo < step:   # a gap under a step between parts: halve it
            mid = (lo + p.start) // 2
            parts[k - 1].stop, p.start = mid, mid
        else:  # at the take's start a foot may be mid-swing: up to a stride
            p.start = max(lo, int(np.floor(p.start - (2 * step if k == 0 else step))))
        if k + 1 == len(parts):
            p.stop = min(T, int(np.ceil(p.stop + 2 * step)))
        elif parts[k + 1].start - p.stop >= step:
            p.stop = int(np.ceil(p.stop + step))


def _fill(motion: Motion, parts: list[Activity], landings: Landings, min_periods: float) -> list[Activity]:
    """The parts with the frames between them (and before the first, after the last) as parts of their own."""
    T = motion.n_frames
    out, at = [], 0
    for p in [*parts, None]:
        stop = T if p is None else p.start
        if stop > at:
            out.extend(_other(motion, at, stop, min_periods, gait_near=bool(parts)))
        if p is not None:
            out.append(p)
            at = p.stop
    return out


def _other(motion: Motion, start: int, stop: int, min_periods: float, gait_near: bool) -> list[Activity]:
    """Frames ``start .. stop-1`` without gait: an arms part, a periodic part, a gesture, standing or a short
    transition between gait parts."""
    n = stop - start
    if n < MIN_OTHER_S * motion.fps:
        kind = "transition" if gait_near else "gesture"
        why = "between activities" if gait_near else "in the whole take"
        return [Activity(start=start, stop=stop, kind=kind, limbs="none",
                         reason=f"only {n} frames ({n * motion.frame_time:.1f} s) {why}: too short to repeat")]
    piece = motion[start:stop]
    spread = _rotation_spread(piece)
    if float(np.sort(spread)[-min(3, spread.size)]) < STILL_DEG:  # fewer than three joints move
        return [Activity(start=start, stop=stop, kind="standing", limbs="none",
                         reason="the actor stands: nothing moves enough to loop")]
    found = _periodic_in(piece, spread, min_periods)
    if found is not None:  # what repeats must move: noise while the actor stands still after a gesture does not
        a, b = found[3]
        if float(_rotation_spread(piece[a:b]).max()) < STILL_DEG:
            found = None
    still = _legs_still(piece.skeleton, spread)
    if found is None:
        return [Activity(start=start, stop=stop, kind="gesture", limbs="none", legs_still=still,
                         reason="no repeating motion: the body moves once, it does not repeat")]
    limbs, kind, pm, (s, e) = found
    out = []
    if s > 0:
        out.extend(_lead(motion, start, start + s, "before"))
    out.append(Activity(start=start + s, stop=start + e, kind=kind, limbs=limbs, period_frames=pm.period_frames,
                        loop=True, periodic=pm, legs_still=still,
                        reason=f"{kind}: {pm.n_periods:.1f} periods of {pm.period_frames:.1f} frames"))
    if e < n:
        out.extend(_lead(motion, start + e, stop, "after"))
    return out


def _lead(motion, start, stop, when):
    return [Activity(start=start, stop=stop, kind="gesture", limbs="none",
                     reason=f"the movement {when} the repeating part: it happens once")]


def _rotation_spread(motion: Motion) -> np.ndarray:
    """Each joint's rotation spread ``(J,)`` in degrees: the RMS angle of its rotations from their mean."""

    q = motion.rotations
    mean = mean_rotations(q)
    ang = quat_angles(q, np.broadcast_to(mean, q.shape))
    return np.degrees(np.sqrt(np.mean(ang ** 2, axis=0)))


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
    """Whether the legs stand: no leg joint's rotation spreads more than twice :data:`STILL_DEG`."""
    try:
        legs = skeleton.select("legs")
    except MocycleError:
        return True
    return not legs or float(spread[legs].max()) < 2 * STILL_DEG


def _repeating_region(piece: Motion, joints, min_periods: float) -> tuple[int, int, float] | None:
    """Where ``joints`` repeat in ``piece``: ``(start, stop, period)`` from the velocity of their rotations
    (a wave's hand swings back and forth while the arm's raise and fall happen once): the period by windowed
    autocorrelation (paper 004), the frames where the take is like itself one period later
    (:func:`~mocycle.phase.period.repetition_distance` under a half) and moves (at least a fifth of its
    largest local speed), their longest run.  ``None`` when it holds fewer than ``min_periods`` periods."""

    X, _ = pose_matrix(piece, rep="expmap", root="drop", joints=joints, normalize=False, weights=None)
    V = np.diff(X, axis=0)
    min_lag = max(2, int(round(0.25 * piece.fps)))
    if V.shape[0] < 2 * min_lag + 2:
        return None
    P = autocorrelation_period(V, min_lag=min_lag)
    if not np.isfinite(P):
        return None
    w = max(3, int(round(P)))
    alike = repetition_distance(V, P, smooth=w) < 0.5
    energy = moving_average((V ** 2).sum(axis=1), w)
    busy = energy > 0.2 * energy.max()
    good = alike & busy
    runs = _true_runs(good)
    if not runs:
        return None
    s, e = max(runs, key=lambda r: r[1] - r[0])
    s, e = max(0, s - w // 2), min(piece.n_frames, e + 1 + w // 2)
    if (e - s) < min_periods * P:
        return None
    return s, e, float(P)


def _true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def _periodic_in(piece: Motion, spread: np.ndarray, min_periods: float):
    """``(limbs, kind, PeriodicMotion, (start, stop))`` of the motion repeating in ``piece`` (frames of the
    piece; the PeriodicMotion is on those frames): the arm joints that move first (a wave beside standing
    legs), where they repeat, then the whole body; ``None`` when nothing repeats."""

    moving = _moving_arm_joints(piece.skeleton, spread) if _legs_still(piece.skeleton, spread) else []
    tries = [(moving, "arms")] if moving else []
    tries.append((None, "periodic"))
    for joints, kind in tries:
        region = _repeating_region(piece, joints, min_periods)
        if region is None:
            if joints is not None:
                continue
            region = (0, piece.n_frames, float("nan"))  # the whole body: the cohomology finds where it repeats
        s, e, acf = region
        sub = piece[s:e]
        limbs = ",".join(joints) if joints else "all"
        try:
            result = find_phase(sub, joints=joints, min_periods=min_periods)
            classes = result.classes
        except (NoPeriodicMotion, MocycleError):
            classes = []
        agree = [c for c in classes if not np.isfinite(acf) or abs(c.period_frames / acf - 1) <= 2 * PERIOD_AGREEMENT]
        if agree:
            pm = max(agree, key=lambda c: len(c.frames()))
            a, b = pm.excitation[0][0], pm.excitation[-1][1]
            return limbs, kind, _rebased(pm, a, b), (s + a, s + b)
        if not np.isfinite(acf) or joints is None:
            continue  # the whole body needs the cohomology's word; an arm that swings on its own, the autocorrelation's
        x = np.arange(e - s, dtype=np.float64) / acf
        why = (f"the autocorrelation of the {'moving arm joints' if joints else 'body'}' velocities: "
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
    ``[start, stop)``: a least-squares line ``t = t0 + P (k/2) + c [foot is the second one]`` over the
    landings' step counts ``k``, so each foot's landings are a whole cycle ``P`` apart.  Returns the time
    (cycles, frame ``start`` first) and ``P`` (frames)."""
    step = part.period_frames / 2.0 if np.isfinite(part.period_frames) else 0.0
    near = (landings_frames >= start - step) & (landings_frames <= stop + step)
    f = landings_frames[near].astype(np.float64)
    foot = landings_foot[near]
    if f.size < 3:
        raise MocycleError(f"a stride phase needs three landings; frames {start}-{stop} have {f.size}")
    k = np.arange(f.size, dtype=np.float64)
    second = (foot != foot[0]).astype(np.float64)
    B = np.column_stack([np.ones_like(k), k / 2.0, second])
    (t0, P, _), *_ = np.linalg.lstsq(B, f, rcond=None)
    if not P > 0:
        raise MocycleError(f"the landings of frames {start}-{stop} give no stride period")
    t = np.arange(start, stop, dtype=np.float64)
    return (t - t0) / P, float(P)
