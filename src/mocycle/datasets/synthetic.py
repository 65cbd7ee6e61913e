"""Synthetic takes with exact ground truth: walk, run, walk-then-run, non-periodic, still.

Every take uses :func:`humanoid_skeleton` (22 joints, Y up, centimetres, facing
+Z, the character's left is +X).  Joint angles are designed per rotation
channel in degrees and turned into quaternions with the joint's own channel
order (intrinsic, e.g. ``"ZYX"``), so a BVH writer that keeps the orders writes
back the designed angles (kept in :attr:`SyntheticTake.euler_deg`).

Gaits are smooth periodic functions of the phase ``u`` (in cycles; one cycle
is a left step plus a right step, left heel strike at phase 0).  The phase is
the integral of the step frequency, so ``phase``, ``unwrapped_phase`` and
``period_frames`` are exact.  Everything is vectorised over frames and
deterministic for a given seed.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cache

import numpy as np
from scipy.ndimage import gaussian_filter1d
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError, OptionError
from ..motion import EndSite, Motion, Skeleton
from ..rotations import euler_to_quats

__all__ = [
    "STEADY_KINDS",
    "SyntheticTake",
    "humanoid_skeleton",
    "synthetic_gesture",
    "synthetic_nonperiodic",
    "synthetic_run",
    "synthetic_circle_walk",
    "synthetic_half_cycle_trap",
    "synthetic_still",
    "synthetic_sway",
    "synthetic_walk",
    "synthetic_walk_then_run",
    "synthetic_walk_then_wave",
    "synthetic_walk_turn_walk",
    "synthetic_wave",
    "to_z_up",
]

_ROOT_CH = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
_ZYX = ("Zrotation", "Yrotation", "Xrotation")
_ZXY = ("Zrotation", "Xrotation", "Yrotation")
_YXZ = ("Yrotation", "Xrotation", "Zrotation")

# name, parent, offset (cm), channels
_JOINTS: tuple[tuple[str, str | None, tuple[float, float, float], tuple[str, ...]], ...] = (
    ("Hips", None, (0.0, 97.0, 0.0), _ROOT_CH),
    ("LeftUpLeg", "Hips", (9.0, -4.0, 0.0), _ZYX),
    ("LeftLeg", "LeftUpLeg", (0.0, -44.0, 0.0), _ZYX),
    ("LeftFoot", "LeftLeg", (0.0, -42.0, 0.0), _ZYX),
    ("LeftToeBase", "LeftFoot", (0.0, -7.0, 13.0), _ZYX),
    ("RightUpLeg", "Hips", (-9.0, -4.0, 0.0), _ZYX),
    ("RightLeg", "RightUpLeg", (0.0, -44.0, 0.0), _ZYX),
    ("RightFoot", "RightLeg", (0.0, -42.0, 0.0), _ZYX),
    ("RightToeBase", "RightFoot", (0.0, -7.0, 13.0), _ZYX),
    ("Spine", "Hips", (0.0, 10.0, 0.0), _ZYX),
    ("Spine1", "Spine", (0.0, 12.0, 0.0), _ZYX),
    ("Spine2", "Spine1", (0.0, 12.0, 0.0), _ZYX),
    ("Neck", "Spine2", (0.0, 15.0, 0.0), _YXZ),
    ("Head", "Neck", (0.0, 10.0, 1.0), _ZYX),
    ("LeftShoulder", "Spine2", (3.0, 11.0, 0.0), _ZYX),
    ("LeftArm", "LeftShoulder", (14.0, 0.0, 0.0), _ZXY),
    ("LeftForeArm", "LeftArm", (28.0, 0.0, 0.0), _ZXY),
    ("LeftHand", "LeftForeArm", (26.0, 0.0, 0.0), _ZYX),
    ("RightShoulder", "Spine2", (-3.0, 11.0, 0.0), _ZYX),
    ("RightArm", "RightShoulder", (-14.0, 0.0, 0.0), _ZXY),
    ("RightForeArm", "RightArm", (-28.0, 0.0, 0.0), _ZXY),
    ("RightHand", "RightForeArm", (-26.0, 0.0, 0.0), _ZYX),
)
_END_SITES = (
    ("Head", (0.0, 18.0, 0.0), "HeadTop"),
    ("LeftHand", (18.0, 0.0, 0.0), "LeftHandEnd"),
    ("RightHand", (-18.0, 0.0, 0.0), "RightHandEnd"),
    ("LeftToeBase", (0.0, 0.0, 6.0), "LeftToeEnd"),
    ("RightToeBase", (0.0, 0.0, 6.0), "RightToeEnd"),
)
_NAMES = tuple(j[0] for j in _JOINTS)
_IX = {n: i for i, n in enumerate(_NAMES)}
_AXIS = {"X": 0, "Y": 1, "Z": 2}
#: Segment labels of steady periodic activities (see :attr:`SyntheticTake.steady_parts`).
STEADY_KINDS = frozenset({"walk", "run", "symmetric walk", "straight", "turning left", "turning right",
                          "wave", "sway"})
#: Standing height of the Hips joint in the rest pose (cm); toes then touch y = 0.
STAND_HEIGHT = 97.0



def _rng(seed) -> np.random.Generator:
    """numpy's generator for ``seed`` (a whole number >= 0), else a MocycleError."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise MocycleError(f"the seed must be a whole number >= 0; got {seed!r}")
    return np.random.default_rng(seed)

def humanoid_skeleton() -> Skeleton:
    """A 22-joint humanoid: Y up, centimetres, facing +Z, left = +X, T-pose at rest.

    The root ``Hips`` has ``Xposition Yposition Zposition Zrotation Yrotation
    Xrotation``; most joints ``ZYX`` rotations, the arms and forearms ``ZXY``
    and the neck ``YXZ``.  End Sites sit on the head top, hands and toes.
    """
    parents = np.array([-1 if p is None else _IX[p] for _, p, _, _ in _JOINTS], dtype=np.int64)
    offsets = np.array([o for _, _, o, _ in _JOINTS], dtype=np.float64)
    sites = tuple(EndSite(_IX[p], off, name) for p, off, name in _END_SITES)
    return Skeleton(_NAMES, parents, offsets, tuple(c for *_, c in _JOINTS), sites)


@dataclass(frozen=True, eq=False)
class SyntheticTake:
    """A synthetic motion with its ground truth.

    Attributes
    ----------
    motion : the take.
    phase : ``(T,)`` true phase in cycles, in ``[0, 1)`` (NaN where undefined).
    unwrapped_phase : ``(T,)`` cumulative cycles (``phase == unwrapped_phase % 1``).
    period_frames : ``(T,)`` instantaneous period in frames (NaN where undefined).
    segments : ``(label, start, stop)`` frame ranges, stop exclusive, covering the take.
    description : one line saying how the take was made.
    euler_deg : ``(T, J, 3)`` the rotation channel values in degrees, in each
        joint's own channel order (what a BVH file of this take should hold).
    heading_deg : ``(T,)`` the body's facing about the world vertical in degrees, from
        the skeleton's forward axis (+Z), positive towards its left (+X, a left turn);
        ``None`` for takes that do not say.
    """

    motion: Motion
    phase: np.ndarray
    unwrapped_phase: np.ndarray
    period_frames: np.ndarray
    segments: list[tuple[str, int, int]]
    description: str
    euler_deg: np.ndarray | None = None
    heading_deg: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return self.motion.n_frames

    @property
    def fps(self) -> float:
        return self.motion.fps

    @property
    def steady_parts(self) -> list[tuple[str, int, int]]:
        """The ``segments`` that hold a steady periodic activity (a gait, turning or not, or a wave);
        transitions, raises, holds and one-off gestures left out."""
        return [seg for seg in self.segments if seg[0] in STEADY_KINDS]


# -- gait design --------------------------------------------------------------


@dataclass(frozen=True)
class _Style:
    """One gait: sagittal leg curves (degrees vs. % of cycle) and amplitudes (deg, cm)."""

    name: str
    hip: tuple[tuple[float, float], ...]  # thigh flexion relative to the pelvis
    knee: tuple[tuple[float, float], ...]  # knee flexion
    pitch: tuple[tuple[float, float], ...]  # foot pitch in the world, toes up (+)
    toe: tuple[tuple[float, float], ...]  # toe extension (toes up relative to the foot)
    pelvis_tilt: float
    pelvis_rot: float
    pelvis_list: float
    lean: float
    trunk_rot: float
    arm_down: float
    arm_swing: float
    elbow_mean: float
    elbow_amp: float
    stride: float  # cm per cycle
    flight: float  # cm of extra root height between stances (run)
    flight_at: float  # phase of the middle of the first flight
    sway: float
    surge: float
    symmetric: bool = False  # no left/right asymmetry (limp, arm swing, head tilt)


# Approximate normative sagittal curves (after Winter's walking data and
# typical running data); fitted with a few harmonics below.
_WALK = _Style(
    name="walk",
    hip=((0, 22), (10, 18), (20, 10), (30, 1), (40, -7), (50, -14), (55, -16), (60, -12),
         (65, -4), (70, 5), (75, 13), (80, 19), (85, 23), (90, 25), (95, 24)),
    knee=((0, 3), (5, 8), (10, 11), (15, 11), (20, 9), (30, 4), (40, 4), (45, 8), (50, 14),
          (55, 22), (60, 35), (65, 48), (70, 58), (75, 61), (80, 57), (85, 43), (90, 25),
          (95, 9)),
    pitch=((0, 15), (5, 5), (10, 0), (40, 0), (47, -4), (52, -10), (57, -22), (62, -38),
           (70, -30), (80, -10), (90, 8), (95, 14)),
    toe=((0, 0), (35, 0), (45, 8), (55, 25), (62, 35), (68, 15), (75, 0)),
    pelvis_tilt=2.0, pelvis_rot=5.0, pelvis_list=4.0, lean=3.0,
    trunk_rot=4.0, arm_down=75.0, arm_swing=18.0, elbow_mean=15.0, elbow_amp=8.0,
    stride=140.0, flight=0.0, flight_at=0.0, sway=2.5, surge=1.0,
)
_RUN = _Style(
    name="run",
    hip=((0, 25), (10, 18), (20, 5), (30, -8), (40, -18), (45, -20), (50, -15), (60, 0),
         (70, 20), (80, 35), (85, 37), (90, 33)),
    knee=((0, 15), (10, 32), (20, 40), (30, 30), (40, 20), (50, 35), (60, 70), (70, 95),
          (75, 100), (80, 90), (90, 50), (95, 25)),
    pitch=((0, 5), (5, 0), (20, 0), (28, -10), (35, -30), (40, -45), (50, -35), (60, -20),
           (75, 0), (88, 10), (95, 8)),
    toe=((0, 0), (22, 0), (30, 10), (36, 35), (42, 20), (50, 0)),
    pelvis_tilt=4.0, pelvis_rot=8.0, pelvis_list=5.0, lean=9.0,
    trunk_rot=8.0, arm_down=70.0, arm_swing=35.0, elbow_mean=80.0, elbow_amp=15.0,
    stride=250.0, flight=5.0, flight_at=0.45, sway=1.5, surge=2.0,
)

# Deliberate left/right asymmetry (a slight limp) so that the pose half a cycle
# later is not the mirror image.
_RIGHT_SCALE = 0.88
_LEFT_ARM_SCALE = 1.2
_N_HARMONICS = 6


def _cos(u: np.ndarray, k: float = 1.0, at: float = 0.0) -> np.ndarray:
    return np.cos(2.0 * np.pi * k * (u - at))


def _sin(u: np.ndarray, k: float = 1.0, at: float = 0.0) -> np.ndarray:
    return np.sin(2.0 * np.pi * k * (u - at))


def _bump(u: np.ndarray, at: float, kappa: float) -> np.ndarray:
    """A periodic (von Mises) bump of height 1 centred on phase ``at``."""
    return np.exp(kappa * (_cos(u, 1.0, at) - 1.0))


@cache
def _fourier(points: tuple[tuple[float, float], ...]) -> np.ndarray:
    """Fourier coefficients ``(K + 1, 2)`` of a periodic curve given as (percent, value)."""
    x = np.array([p[0] for p in points]) / 100.0
    y = np.array([p[1] for p in points], dtype=np.float64)
    grid = np.arange(256) / 256.0
    spec = np.fft.rfft(np.interp(grid, x, y, period=1.0)) / 256.0
    c = np.zeros((_N_HARMONICS + 1, 2))
    c[0, 0] = spec[0].real
    c[1:, 0] = 2.0 * spec[1:_N_HARMONICS + 1].real
    c[1:, 1] = -2.0 * spec[1:_N_HARMONICS + 1].imag
    return c


def _curve(points: tuple[tuple[float, float], ...], u: np.ndarray) -> np.ndarray:
    """The smooth periodic curve through ``points`` (a few harmonics) at phases ``u``."""
    c = _fourier(points)
    k = 2.0 * np.pi * np.arange(1, c.shape[0]) * u[:, None]
    return c[0, 0] + np.cos(k) @ c[1:, 0] + np.sin(k) @ c[1:, 1]


def _gait_angles(style: _Style, u: np.ndarray) -> np.ndarray:
    """Designed joint angles ``(T, J, 3)`` in degrees, indexed by axis (x, y, z)."""
    s = style
    a = np.zeros((u.shape[0], len(_NAMES), 3))

    def put(name: str, axis: str, values: np.ndarray | float) -> None:
        a[:, _IX[name], _AXIS[axis]] += values

    tilt = s.pelvis_tilt * (1.0 + _cos(u, 2, 0.1))
    right_scale, left_arm_scale = (1.0, 1.0) if s.symmetric else (_RIGHT_SCALE, _LEFT_ARM_SCALE)
    for side, shift, sign, scale in (("Left", 0.0, 1.0, 1.0), ("Right", 0.5, -1.0, right_scale)):
        v = u - shift  # this leg's own phase: heel strike at 0
        hip = scale * _curve(s.hip, v)
        knee = scale * _curve(s.knee, v)
        put(f"{side}UpLeg", "X", -hip)  # flexion: thigh forward (+Z)
        put(f"{side}UpLeg", "Y", sign * 4.0 * _sin(v, 1, 0.1))
        put(f"{side}UpLeg", "Z", sign * (2.0 + 3.0 * _cos(v, 1, 0.3)))
        put(f"{side}Leg", "X", knee)  # flexion: shank backward
        put(f"{side}Leg", "Y", sign * 2.0 * _sin(v, 1, 0.2))
        # the ankle makes the foot's world pitch follow the design (flat in stance);
        # negative X lifts the toes
        put(f"{side}Foot", "X", hip - knee - tilt - _curve(s.pitch, v))
        put(f"{side}Foot", "Z", sign * 3.0 * _sin(v, 1))
        put(f"{side}ToeBase", "X", -_curve(s.toe, v))

    # pelvis (root rotation); heading is added by the caller
    put("Hips", "X", tilt)
    put("Hips", "Y", -s.pelvis_rot * _cos(u))  # left hip forward at left heel strike
    put("Hips", "Z", s.pelvis_list * _sin(u, 1, 0.05))  # left side up in left stance

    # trunk counter-rotates against the pelvis, leans forward a little
    for j, w in (("Spine", 0.3), ("Spine1", 0.35), ("Spine2", 0.35)):
        put(j, "X", w * (s.lean + 1.5 * _cos(u, 2, 0.2)))
        put(j, "Y", w * s.trunk_rot * _cos(u, 1, 0.03))
        put(j, "Z", w * (-s.pelvis_list * _sin(u, 1, 0.1) + 2.0))  # constant side bend
    put("Neck", "X", -0.5 * s.lean - 1.0 * _cos(u, 2, 0.3))
    put("Neck", "Y", -0.3 * s.trunk_rot * _cos(u))
    put("Head", "X", -0.3 * s.lean + 1.5 * _sin(u, 2))
    put("Head", "Z", 3.0 + (0.0 if s.symmetric else 1.0) * _sin(u))  # a slight head tilt

    # arms: lowered from the T-pose, counter-swinging with the legs
    for side, shift, sign, scale in (("Left", 0.5, 1.0, left_arm_scale), ("Right", 0.0, -1.0, 1.0)):
        v = u - shift  # this arm is furthest forward at v = 0
        put(f"{side}Shoulder", "Z", sign * 2.0 * _cos(v, 2, 0.1))
        put(f"{side}Shoulder", "Y", -sign * 2.0 * _cos(v))
        put(f"{side}Arm", "Z", -sign * s.arm_down)
        put(f"{side}Arm", "Y", -sign * (5.0 + scale * s.arm_swing * _cos(v, 1, 0.02)))
        put(f"{side}Arm", "X", 4.0 * _sin(v))
        put(f"{side}ForeArm", "Y", -sign * (s.elbow_mean + scale * s.elbow_amp * _cos(v, 1, 0.08)))
        put(f"{side}Hand", "Z", -sign * (5.0 + 3.0 * _cos(v, 1, 0.15)))
        put(f"{side}Hand", "X", 3.0 * _sin(v, 2))
    return a


_GRID = 256
_HEEL = np.array([0.0, -7.0, -4.0])  # heel point below the ankle (cm, foot frame)


def _floor_height(skel: Skeleton, q: np.ndarray) -> np.ndarray:
    """Root height ``(T,)`` (cm) that puts the lower foot on the floor (y = 0).

    ``q``: ``(T, J, 4)`` local rotations.  Each foot's lowest point (heel, ball,
    toe tip) is measured below the root; a soft maximum over the two feet
    (0.5 cm temperature) keeps the result smooth.
    """
    T = q.shape[0]
    R, P = Motion(skel, q, None, 1.0, root_positions=np.zeros((T, 3))).world_transforms()
    tip = {s.parent: np.asarray(s.offset) for s in skel.end_sites}
    depth = []
    for side in ("Left", "Right"):
        f, t = _IX[f"{side}Foot"], _IX[f"{side}ToeBase"]
        heel = P[:, f] + R[:, f] @ _HEEL
        toe = P[:, t] + R[:, t] @ tip[t]
        depth.append(-np.min(np.stack([heel[:, 1], P[:, t, 1], toe[:, 1]]), axis=0))
    c = np.stack(depth, axis=1)
    tau = 0.5
    m = c.max(axis=1)
    return m + tau * np.log(np.sum(np.exp((c - m[:, None]) / tau), axis=1))


@cache
def _height_table(style: _Style) -> np.ndarray:
    """Root height (cm) of the noise-free gait on a grid of ``_GRID`` phases.

    The floor height (:func:`_floor_height`) plus, for running, flight bumps
    between the stances, low-passed to 10 harmonics and lifted so that no foot
    goes below the floor.
    """
    u = np.arange(_GRID) / _GRID
    skel = humanoid_skeleton()
    floor = _floor_height(skel, _quats(skel, _gait_angles(style, u))[0])
    h = floor + style.flight * (_bump(u, style.flight_at, 8.0) + _bump(u, style.flight_at + 0.5,
                                                                        8.0))
    spec = np.fft.rfft(h)
    spec[11:] = 0.0
    h = np.fft.irfft(spec, _GRID)
    h += max(0.0, float(np.max(floor - h)))
    h.setflags(write=False)
    return h


def _root_height(style: _Style, u: np.ndarray) -> np.ndarray:
    """Root height ``(T,)`` in cm at phases ``u`` (a function of phase only)."""
    grid = np.arange(_GRID) / _GRID
    return np.interp(u - np.floor(u), grid, _height_table(style), period=1.0)


def _gait_root(style: _Style, u: np.ndarray, heading_deg: np.ndarray) -> np.ndarray:
    """Root positions ``(T, 3)`` in cm: travel along the heading (from +Z), bob, sway."""
    s = style
    along = s.stride * (u - u[0]) + s.surge * (_sin(u, 2) - _sin(u[:1], 2))
    h = np.deg2rad(heading_deg)
    step = np.diff(along)
    hm = 0.5 * (h[1:] + h[:-1])
    x = np.concatenate([[0.0], np.cumsum(step * np.sin(hm))])
    z = np.concatenate([[0.0], np.cumsum(step * np.cos(hm))])
    lateral = s.sway * _sin(u)  # towards the stance leg (left = +X)
    x = x + lateral * np.cos(h)
    z = z - lateral * np.sin(h)
    return np.stack([x, _root_height(s, u), z], axis=1)


def _channels(skel: Skeleton, angles_xyz: np.ndarray) -> np.ndarray:
    """Angles ``(T, J, 3)`` indexed by axis (x, y, z) reordered into each joint's channel order."""
    chan = np.empty_like(angles_xyz)
    for j in range(angles_xyz.shape[1]):
        chan[:, j] = angles_xyz[:, j, [_AXIS[c] for c in skel.euler_order(j)]]
    return chan


def _quats(skel: Skeleton, angles_xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quaternions ``(T, J, 4)`` and channel-order angles ``(T, J, 3)`` from (x, y, z) degrees."""
    chan = _channels(skel, angles_xyz)
    return _quats_from_channels(skel, chan), chan


def _turn_root(skel: Skeleton, chan: np.ndarray, heading_deg: np.ndarray) -> None:
    """Turn the root by ``heading_deg`` (T,) about the world vertical, in place in ``chan``."""
    order = skel.euler_order(0)
    turned = Rotation.from_euler("y", heading_deg[:, None], degrees=True) * Rotation.from_euler(
        order, chan[:, 0], degrees=True)
    chan[:, 0] = turned.as_euler(order, degrees=True)


def _quats_from_channels(skel: Skeleton, chan: np.ndarray) -> np.ndarray:
    """Quaternions ``(T, J, 4)`` from rotation channel values ``(T, J, 3)`` in degrees."""
    T, J, _ = chan.shape
    groups: dict[str, list[int]] = {}
    for j in range(J):
        groups.setdefault(skel.euler_order(j), []).append(j)
    q = np.empty((T, J, 4))
    for order, js in groups.items():  # one call per Euler order
        q[:, js] = euler_to_quats(chan[:, js], order, degrees=True)
    return q


def _check(n_frames: int, fps: float) -> tuple[int, float]:
    try:
        ok = int(n_frames) == n_frames and n_frames >= 1
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise OptionError("n_frames", f"must be a positive integer; got {n_frames!r}")
    return int(n_frames), _validate.positive("fps", fps)


def _phase_truth(n_frames: int, fps: float, period_s: float, speed_change: float,
                 phase0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unwrapped phase, wrapped phase and period in frames for a linear frequency ramp."""
    _validate.positive("period_s", period_s)
    if not np.isfinite(phase0):
        raise MocycleError(f"phase0 must be a finite number of cycles; got {phase0!r}")
    _validate.real("speed_change", speed_change, -1.0, low_open=True)  # the frequency must stay positive
    t = np.arange(n_frames) / fps
    span = max((n_frames - 1) / fps, 1.0 / fps)
    f0 = 1.0 / period_s
    rate = speed_change / span  # relative frequency change per second
    unwrapped = phase0 + f0 * (t + 0.5 * rate * t * t)
    freq = f0 * (1.0 + rate * t)
    return unwrapped, _wrap(unwrapped), fps / freq


def _wrap(u: np.ndarray) -> np.ndarray:
    p = u - np.floor(u)
    p[p >= 1.0] = 0.0
    return p


def _gait_take(style: _Style, n_frames, fps, period_s, noise_deg, drift, speed_change, phase0,
               seed) -> SyntheticTake:
    n_frames, fps = _check(n_frames, fps)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    if not np.isfinite(drift):
        raise MocycleError(f"drift must be a finite number; got {drift!r}")
    u, phase, period = _phase_truth(n_frames, fps, float(period_s), float(speed_change),
                                    float(phase0))
    skel = humanoid_skeleton()
    ang = _gait_angles(style, u)
    t = np.arange(n_frames) / fps
    heading = np.zeros(n_frames)
    if drift:
        for j in ("Spine", "Spine1", "Spine2"):
            ang[:, _IX[j], 0] += drift * t / 3.0  # drift deg/s of forward lean in total
    chan = _channels(skel, ang)
    if drift:
        # turn the whole body about the vertical axis; the path curves along
        heading = 3.0 * drift * t  # degrees
        _turn_root(skel, chan, heading)
    if noise_deg > 0:
        chan += _rng(seed).normal(0.0, noise_deg, size=chan.shape)
    q = _quats_from_channels(skel, chan)
    root = _gait_root(style, u, heading)
    motion = Motion(skel, q, None, 1.0 / fps, root_positions=root)
    desc = (f"synthetic {style.name}: {n_frames} frames at {fps:g} fps, period {period_s:g} s, "
            f"speed change {speed_change:+g}, noise {noise_deg:g} deg, drift {drift:g}, "
            f"phase0 {phase0:g}, seed {seed}")
    return SyntheticTake(motion, phase, u, period, [(style.name, 0, n_frames)], desc, chan, heading)


# -- public generators ----------------------------------------------------------


def synthetic_walk(n_frames: int = 600, fps: float = 60.0, period_s: float = 1.0,
                   noise_deg: float = 0.0, drift: float = 0.0, speed_change: float = 0.0,
                   phase0: float = 0.0, seed: int = 0) -> SyntheticTake:
    """A walk with exact phase ground truth.

    ``period_s``: seconds per cycle (left + right step) at the start.
    ``speed_change``: relative change of step frequency from the first to the
    last frame (0.2 = 20 % faster at the end; the frequency ramps linearly).
    ``noise_deg``: std of Gaussian noise added to every rotation channel (degrees).
    ``drift``: slow posture drift; per second, ``drift`` degrees of extra spine
    lean and ``3 * drift`` degrees of turn about the vertical (the whole body
    and its path turn; the root's channels are re-decomposed, so they may jump
    by 180 degrees once the heading passes 90 degrees).
    ``phase0``: phase of the first frame in cycles.  Stride 140 cm per cycle.
    """
    return _gait_take(_WALK, n_frames, fps, period_s, noise_deg, drift, speed_change, phase0,
                      seed)


def synthetic_run(n_frames: int = 600, fps: float = 60.0, period_s: float = 0.7,
                  noise_deg: float = 0.0, drift: float = 0.0, speed_change: float = 0.0,
                  phase0: float = 0.0, seed: int = 0) -> SyntheticTake:
    """A run (same parameters as :func:`synthetic_walk`): larger amplitudes, flexed
    elbows, stronger arm swing, a flight phase (root highest between stances).
    Stride 250 cm per cycle."""
    return _gait_take(_RUN, n_frames, fps, period_s, noise_deg, drift, speed_change, phase0,
                      seed)


def synthetic_still(n_frames: int = 300, fps: float = 60.0, noise_deg: float = 0.0,
                    seed: int = 0) -> SyntheticTake:
    """The rest T-pose held still (optionally with Gaussian angle noise, degrees)."""
    n_frames, fps = _check(n_frames, fps)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    skel = humanoid_skeleton()
    ang = np.zeros((n_frames, skel.n_joints, 3))
    if noise_deg > 0:
        ang += _rng(seed).normal(0.0, noise_deg, size=ang.shape)
    q, chan = _quats(skel, ang)
    root = np.tile([0.0, STAND_HEIGHT, 0.0], (n_frames, 1))
    nan = np.full(n_frames, np.nan)
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), nan, nan.copy(),
                         nan.copy(), [("still", 0, n_frames)],
                         f"synthetic still T-pose: {n_frames} frames at {fps:g} fps, "
                         f"noise {noise_deg:g} deg, seed {seed}", chan)


def synthetic_gesture(n_frames: int = 240, fps: float = 60.0, noise_deg: float = 0.5,
                      seed: int = 0, hand: str = "both") -> SyntheticTake:
    """A one-off gesture: standing with the arms down, the hands (``hand``: ``"both"``, ``"left"`` or
    ``"right"``) raised above the head once and lowered.

    The raise takes the middle 40 % of the take (up, a short hold, down, smoothstep ramps); the rest is
    standing still with Gaussian angle noise (``noise_deg``).  Nothing repeats: a take that stretching
    and looping must refuse.  ``segments``: ``still``, ``gesture``, ``still``.
    """
    n_frames, fps = _check(n_frames, fps)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    if hand not in _HANDS:
        raise MocycleError(f"hand must be 'left', 'right' or 'both'; got {hand!r}")
    skel = humanoid_skeleton()
    t = np.arange(n_frames) / max(n_frames - 1, 1)
    a, b = 0.3, 0.7                                    # the gesture's span (fractions of the take)
    up = np.clip((t - a) / (0.35 * (b - a)), 0.0, 1.0)
    down = np.clip((b - t) / (0.35 * (b - a)), 0.0, 1.0)
    lift = _smoothstep(np.minimum(up, down))           # 0 standing, 1 hands above the head
    ang = np.zeros((n_frames, skel.n_joints, 3))
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        raised = lift if side in _HANDS[hand] else np.zeros(n_frames)
        ang[:, _IX[f"{side}Arm"], _AXIS["Z"]] = sign * (-75.0 + 160.0 * raised)
        ang[:, _IX[f"{side}ForeArm"], _AXIS["Y"]] = -sign * (15.0 + 20.0 * np.sin(np.pi * raised))
    ang[:, _IX["Spine1"], _AXIS["X"]] = -4.0 * lift   # a slight lean back with the hands up
    if noise_deg > 0:
        ang += np.random.default_rng(seed).normal(0.0, noise_deg, size=ang.shape)
    q, chan = _quats(skel, ang)
    root = np.tile([0.0, STAND_HEIGHT, 0.0], (n_frames, 1))
    nan = np.full(n_frames, np.nan)
    i, j = int(round(a * (n_frames - 1))), int(round(b * (n_frames - 1))) + 1
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), nan, nan.copy(), nan.copy(),
                         [("still", 0, i), ("gesture", i, j), ("still", j, n_frames)],
                         f"synthetic gesture ({hand} hand(s) raised once): {n_frames} frames at {fps:g} fps, "
                         f"noise {noise_deg:g} deg, seed {seed}", chan)


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, ...], sigma: float,
                  walk: bool) -> np.ndarray:
    """Gaussian-filtered white noise (or random walk) along axis 0, zero mean, unit std."""
    x = rng.normal(size=shape)
    if walk:
        x = np.cumsum(x, axis=0)
    x = gaussian_filter1d(x, sigma, axis=0, mode="nearest")
    x = x - x.mean(axis=0)
    sd = x.std(axis=0)
    return x / np.where(sd > 1e-12, sd, 1.0)


def synthetic_nonperiodic(n_frames: int = 600, fps: float = 60.0, seed: int = 0) -> SyntheticTake:
    """Smooth random joint trajectories and a wandering root (a negative example).

    Each rotation channel is the walk's mean angle plus low-pass filtered random
    walk and noise scaled to the walk's standard deviation for that channel
    (at least 3 degrees).  The root wanders on a smooth random path at
    0.3-1.2 m/s, facing where it goes, its height keeping the lower foot on
    the floor.  ``phase``,
    ``unwrapped_phase`` and ``period_frames`` are all NaN.
    """
    n_frames, fps = _check(n_frames, fps)
    rng = _rng(seed)
    skel = humanoid_skeleton()
    ref = _gait_angles(_WALK, np.arange(120) / 120.0)
    mean, sd = ref.mean(axis=0), np.maximum(ref.std(axis=0), 3.0)
    shape = (n_frames, skel.n_joints, 3)
    z = (0.7 * _smooth_noise(rng, shape, 0.3 * fps, walk=True)
         + 0.7 * _smooth_noise(rng, shape, 0.12 * fps, walk=False))
    chan = _channels(skel, mean + sd * z)
    heading = 60.0 * _smooth_noise(rng, (n_frames,), 0.5 * fps, walk=True)
    _turn_root(skel, chan, heading)  # the body faces where it goes
    q = _quats_from_channels(skel, chan)
    speed = np.clip(75.0 + 30.0 * _smooth_noise(rng, (n_frames,), 0.4 * fps, walk=False),
                    30.0, 120.0)  # cm/s
    h = np.deg2rad(heading)
    x = np.concatenate([[0.0], np.cumsum(speed[:-1] * np.sin(h[:-1]))]) / fps
    zz = np.concatenate([[0.0], np.cumsum(speed[:-1] * np.cos(h[:-1]))]) / fps
    root = np.stack([x, _floor_height(skel, q), zz], axis=1)
    nan = np.full(n_frames, np.nan)
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), nan, nan.copy(),
                         nan.copy(), [("nonperiodic", 0, n_frames)],
                         f"synthetic non-periodic: {n_frames} frames at {fps:g} fps, seed {seed}",
                         chan)


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def synthetic_walk_then_run(n_walk: int = 600, n_run: int = 600, fps: float = 60.0,
                            blend_frames: int = 30, seed: int = 0,
                            noise_deg: float = 0.0) -> SyntheticTake:
    """A walk (1.0 s cycles) turning into a run (0.7 s cycles) in one take.

    The switch is at frame ``n_walk``; rotations are slerped over
    ``blend_frames`` frames centred on it, where ``phase``, ``unwrapped_phase``
    and ``period_frames`` are NaN.  The run's phase is aligned with the walk's
    at the switch and ``unwrapped_phase`` carries on from the walk.  The root's
    horizontal velocity is blended (its path stays continuous) and its height
    keeps a foot on the floor.  ``noise_deg`` adds Gaussian noise (degrees) to
    every rotation channel.  ``segments``: ``[("walk", 0, n_walk), ("run", n_walk, T)]``.
    """
    n_walk, fps = _check(n_walk, fps)
    n_run, _ = _check(n_run, fps)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    blend_frames = int(blend_frames)
    if blend_frames < 0 or blend_frames > min(n_walk, n_run):
        raise MocycleError(f"blend_frames must be between 0 and {min(n_walk, n_run)}; "
                           f"got {blend_frames}")
    T = n_walk + n_run
    k = np.arange(T)
    t = k / fps
    f_w, f_r = 1.0, 1.0 / 0.7  # cycles per second
    mid = n_walk / fps
    u_mid = f_w * mid
    walk = synthetic_walk(T, fps, period_s=1.0 / f_w)
    run = synthetic_run(T, fps, period_s=1.0 / f_r, phase0=(u_mid - f_r * mid) % 1.0)

    lo = n_walk - blend_frames // 2
    if blend_frames > 0:
        w = _smoothstep((k - lo + 0.5) / blend_frames)
    else:
        w = (k >= n_walk).astype(float)
    inside = (w > 0.0) & (w < 1.0)
    skel = walk.motion.skeleton
    J = skel.n_joints
    assert walk.euler_deg is not None and run.euler_deg is not None  # synthetic gaits keep their channels

    # rotations: channel values of whichever gait is active, slerp inside the blend
    chan = np.where((w < 0.5)[:, None, None], walk.euler_deg, run.euler_deg)
    q_clean = np.where((w < 0.5)[:, None, None], walk.motion.rotations, run.motion.rotations)
    if np.any(inside):
        r0 = Rotation.from_quat(walk.motion.rotations[inside].reshape(-1, 4))
        r1 = Rotation.from_quat(run.motion.rotations[inside].reshape(-1, 4))
        ww = np.repeat(w[inside], J)[:, None]
        qb = (r0 * Rotation.from_rotvec(ww * (r0.inv() * r1).as_rotvec())).as_quat()
        q_clean[inside] = qb.reshape(-1, J, 4)
        for j in range(J):
            chan[inside, j] = Rotation.from_quat(q_clean[inside, j]).as_euler(
                skel.euler_order(j), degrees=True)
    if noise_deg > 0:
        chan = chan + _rng(seed).normal(0.0, noise_deg, size=chan.shape)
        q = _quats_from_channels(skel, chan)
    else:
        q = q_clean

    # root: blend the horizontal velocity; height from the (noise-free) pose
    p0, p1 = walk.motion.root_positions, run.motion.root_positions
    v = (1.0 - w[1:, None]) * np.diff(p0, axis=0) + w[1:, None] * np.diff(p1, axis=0)
    root = np.concatenate([p0[:1], p0[:1] + np.cumsum(v, axis=0)])
    root[:, 1] = np.where(w < 0.5, p0[:, 1], p1[:, 1])
    if np.any(inside):
        wi = w[inside]
        lift0 = p0[inside, 1] - _floor_height(skel, walk.motion.rotations[inside])
        lift1 = p1[inside, 1] - _floor_height(skel, run.motion.rotations[inside])
        root[inside, 1] = (_floor_height(skel, q_clean[inside])
                           + (1.0 - wi) * lift0 + wi * lift1)

    walking = k < n_walk
    u = np.where(walking, f_w * t, u_mid + f_r * (t - mid))
    period = np.where(walking, fps / f_w, fps / f_r)
    u[inside] = np.nan
    period[inside] = np.nan
    phase = np.full(T, np.nan)
    phase[~inside] = _wrap(u[~inside])
    desc = (f"synthetic walk then run: {n_walk} walk + {n_run} run frames at {fps:g} fps, "
            f"blend {blend_frames} frames, noise {noise_deg:g} deg, seed {seed}")
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), phase, u, period,
                         [("walk", 0, n_walk), ("run", n_walk, T)], desc, chan)


def to_z_up(motion: Motion) -> Motion:
    """The same take on a Z-up world: the root's rotation and path turned +90 degrees about X (Y -> Z)."""
    W = Rotation.from_euler("x", 90.0, degrees=True)
    q = motion.rotations.copy()
    q[:, 0] = (W * Rotation.from_quat(q[:, 0])).as_quat()
    return motion.replace(rotations=q, tracks={0: W.apply(np.array(motion.root_positions))})


def synthetic_circle_walk(n_frames: int = 600, fps: float = 60.0, period_s: float = 1.0,
                          turn_per_cycle_deg: float = 45.0, noise_deg: float = 0.0, run: bool = False,
                          up: str = "y", seed: int = 0) -> SyntheticTake:
    """A walk (or run) along a circle: the body and its path turn ``turn_per_cycle_deg`` degrees per cycle.

    The heading is tied to the phase (``turn_per_cycle_deg * cycles walked``), so the turn per cycle and
    the period (``period_s``) are exact; the radius is ``stride / turn`` (140 cm per cycle for the walk,
    250 cm for the run).  ``up="z"`` gives the same take on a Z-up world (:func:`to_z_up`).
    ``noise_deg``: Gaussian noise on every rotation channel (degrees).
    """
    n_frames, fps = _check(n_frames, fps)
    if not np.isfinite(turn_per_cycle_deg):
        raise MocycleError(f"turn_per_cycle_deg must be a finite number; got {turn_per_cycle_deg!r}")
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    if up not in ("y", "z"):
        raise MocycleError(f"up must be 'y' or 'z'; got {up!r}")
    style = _RUN if run else _WALK
    u, phase, period = _phase_truth(n_frames, fps, float(period_s), 0.0, 0.0)
    skel = humanoid_skeleton()
    chan = _channels(skel, _gait_angles(style, u))
    heading = float(turn_per_cycle_deg) * u
    _turn_root(skel, chan, heading)
    if noise_deg > 0:
        chan += np.random.default_rng(seed).normal(0.0, noise_deg, size=chan.shape)
    motion = Motion(skel, _quats_from_channels(skel, chan), None, 1.0 / fps,
                    root_positions=_gait_root(style, u, heading))
    if up == "z":
        motion = to_z_up(motion)
    desc = (f"synthetic {style.name} along a circle: {n_frames} frames at {fps:g} fps, period {period_s:g} s, "
            f"turn {turn_per_cycle_deg:g} deg per cycle, noise {noise_deg:g} deg, {up.upper()} up, seed {seed}")
    return SyntheticTake(motion, phase, u, period, [(style.name, 0, n_frames)], desc, chan, heading)


def synthetic_half_cycle_trap(n_frames: int = 600, fps: float = 60.0, period_s: float = 1.0,
                              noise_deg: float = 0.0, seed: int = 0) -> SyntheticTake:
    """A walk whose trunk and root move once per *step*: a trap for phases that wrap twice per cycle.

    The gait of :func:`synthetic_walk` made exactly left/right symmetric (no limp, equal arm swing, no head
    tilt) and without the trunk and root motions that follow the cycle (pelvis rotation and list, trunk
    rotation, sideways sway).  The spine, the root's height, tilt and speed then repeat every step (half a
    cycle), and the left and right step look the same to them; only the legs and arms tell the steps apart.
    ``period_frames`` is the full cycle (two steps).
    """
    style = replace(_WALK, name="symmetric walk", pelvis_rot=0.0, pelvis_list=0.0, trunk_rot=0.0, sway=0.0,
                    symmetric=True)
    return _gait_take(style, n_frames, fps, period_s, noise_deg, 0.0, 0.0, 0.0, seed)


# -- takes that change what they do (issue 28) ----------------------------------


def _turn_profile(s: np.ndarray, taper: float = 0.25) -> np.ndarray:
    """Fraction of the turn done at ``s`` in [0, 1] of the turning part (0 before, 1 after).

    The heading rate is a plateau with raised-cosine tapers over the first and last ``taper`` of the part,
    so the heading and its rate are smooth (no kink where the turn starts or ends).
    """
    s = np.clip(s, 0.0, 1.0)
    r = taper

    def rise(x: np.ndarray) -> np.ndarray:  # integral of the taper, x in [0, r]
        return 0.5 * (x - r / np.pi * np.sin(np.pi * x / r))

    area = 1.0 - r
    f = np.where(s < r, rise(np.minimum(s, r)), 0.5 * r + (s - r))
    f = np.where(s > 1.0 - r, area - rise(np.minimum(1.0 - s, r)), f)
    return f / area


def synthetic_walk_turn_walk(n_before_s: float = 4.0, turn_deg: float = 90.0, turn_strides: float = 2.0,
                             n_after_s: float = 4.0, fps: float = 60.0, period_s: float = 1.0,
                             noise_deg: float = 1.0, seed: int = 0) -> SyntheticTake:
    """A walk that goes straight, turns ``turn_deg`` degrees within ``turn_strides`` strides, and goes straight on.

    ``n_before_s`` / ``n_after_s``: seconds of straight walking before and after the turn; ``turn_deg``:
    the turn in degrees, positive to the left, negative to the right; ``turn_strides``: the turn's length in
    cycles (one cycle = a left and a right step = ``period_s`` seconds).  The gait is
    :func:`synthetic_walk`'s (140 cm per cycle) at a constant period; the body and its path turn together
    (as in :func:`synthetic_circle_walk`), the heading rate a plateau with smooth (raised-cosine) ends.
    ``noise_deg``: Gaussian noise on every rotation channel (degrees).

    Truth: ``heading_deg`` ``(T,)`` per frame (0 before the turn, ``turn_deg`` after); ``period_frames``
    ``period_s * fps`` on every frame; ``segments`` ``[("straight", 0, b), ("turning left", b, c),
    ("straight", c, T)]`` (``"turning right"`` for a negative turn; frames ``[b, c)`` are those where the
    heading changes).
    """
    fps = _validate.positive("fps", fps)
    period_s = _validate.positive("period_s", period_s)
    for name, v in (("n_before_s", n_before_s), ("n_after_s", n_after_s)):
        if not np.isfinite(v) or v < 0:
            raise MocycleError(f"{name} must be >= 0 seconds; got {v!r}")
    if not np.isfinite(turn_deg):
        raise MocycleError(f"turn_deg must be a finite number; got {turn_deg!r}")
    _validate.positive("turn_strides", turn_strides)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    b = int(round(n_before_s * fps))
    c = b + max(2, int(round(turn_strides * period_s * fps)))
    T, _ = _check(c + int(round(n_after_s * fps)), fps)
    u, phase, period = _phase_truth(T, fps, float(period_s), 0.0, 0.0)
    k = np.arange(T, dtype=np.float64)
    heading = float(turn_deg) * _turn_profile((k - b + 0.5) / (c - b))
    skel = humanoid_skeleton()
    chan = _channels(skel, _gait_angles(_WALK, u))
    _turn_root(skel, chan, heading)
    if noise_deg > 0:
        chan += _rng(seed).normal(0.0, noise_deg, size=chan.shape)
    motion = Motion(skel, _quats_from_channels(skel, chan), None, 1.0 / fps,
                    root_positions=_gait_root(_WALK, u, heading))
    turning = "straight" if turn_deg == 0 else ("turning left" if turn_deg > 0 else "turning right")
    segments = [("straight", 0, b), (turning, b, c), ("straight", c, T)]
    segments = [s for s in segments if s[2] > s[1]]
    desc = (f"synthetic walk, turn {turn_deg:+g} deg in {turn_strides:g} strides, walk: {T} frames at {fps:g} fps "
            f"(straight {b}, turning {c - b}, straight {T - c}), period {period_s:g} s, noise {noise_deg:g} deg, "
            f"seed {seed}")
    return SyntheticTake(motion, phase, u, period, segments, desc, chan, heading)


_HANDS = {"left": ("Left",), "right": ("Right",), "both": ("Left", "Right")}


def _stand_angles(n: int, fps: float, lift: dict[str, np.ndarray], wave: dict[str, np.ndarray]
                  ) -> np.ndarray:
    """Standing angles ``(n, J, 3)`` (degrees, by axis x, y, z): legs straight, a slow sway in the trunk.

    ``lift[side]`` ``(n,)`` in [0, 1] raises that arm from hanging (0) to the waving pose (1): upper arm out
    to the side 25 degrees above the horizontal and a little forward, forearm 80 degrees up (the hand a
    little outward); ``wave[side]`` ``(n,)``
    is the forearm's swing about the waving pose in degrees (in the body's frontal plane).
    """
    a = np.zeros((n, len(_NAMES), 3))
    t = np.arange(n) / fps
    # small sway: the trunk and head move slowly, at periods unrelated to the wave; the legs and root stand
    a[:, _IX["Spine"], 2] = 1.2 * np.sin(2 * np.pi * t / 3.7)
    a[:, _IX["Spine1"], 0] = 1.0 + 0.8 * np.sin(2 * np.pi * t / 5.3 + 1.0)
    a[:, _IX["Head"], 0] = 1.5 * np.sin(2 * np.pi * t / 4.1 + 2.0)
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        up = lift.get(side, np.zeros(n))
        sw = wave.get(side, np.zeros(n))
        a[:, _IX[f"{side}UpLeg"], 2] = sign * 2.0        # feet a little apart
        a[:, _IX[f"{side}Foot"], 2] = -sign * 2.0
        a[:, _IX[f"{side}Arm"], 2] = sign * (-75.0 + 100.0 * up)
        a[:, _IX[f"{side}Arm"], 1] = -sign * 20.0 * up   # a little forward
        a[:, _IX[f"{side}ForeArm"], 1] = -sign * 15.0 * (1.0 - up)
        a[:, _IX[f"{side}ForeArm"], 2] = sign * (55.0 * up + sw)  # forearm 80 deg up, hand outward
        a[:, _IX[f"{side}Hand"], 2] = sign * 0.4 * sw
    return a


def synthetic_wave(n_frames: int = 360, fps: float = 60.0, hand: str = "right", wave_period_s: float = 0.6,
                   n_waves: float | None = None, raise_s: float = 0.5, noise_deg: float = 0.5,
                   seed: int = 0) -> SyntheticTake:
    """A hand wave with standing legs: one arm (or both) raised and waving, the legs and root still.

    ``hand``: ``"right"``, ``"left"`` or ``"both"`` (both wave in mirror image).  The waving arm's upper arm
    is held out to the side, its forearm up, swinging 25 degrees either way in the frontal plane every
    ``wave_period_s`` seconds (elbow angle, hand height and the hand's side-to-side position all repeat at
    that period).  ``raise_s`` seconds (0 for none) raise the arm from hanging before the waving and lower
    it after (a one-off lead-in and lead-out); the swing fades in and out over a quarter wave then.
    ``n_waves``: number of waves (then the rest of the take stands still, split before and after); ``None``
    waves for all the frames the raise and lower leave.  The trunk and head sway slowly (periods 3.7-5.3
    s); the root stays at :data:`STAND_HEIGHT` (toes on the floor).  ``noise_deg``: Gaussian noise on every
    rotation channel (degrees).

    Truth: ``segments`` ``("stand", ...)``, ``("raise", ...)``, ``("wave", a, b)``, ``("lower", ...)``,
    ``("stand", ...)`` (empty ones left out); ``phase``/``unwrapped_phase`` count waves from frame ``a``
    (NaN outside the waving); ``period_frames`` ``wave_period_s * fps`` in the waving, NaN elsewhere;
    ``heading_deg`` zeros.
    """
    n_frames, fps = _check(n_frames, fps)
    if hand not in _HANDS:
        raise MocycleError(f"hand must be 'left', 'right' or 'both'; got {hand!r}")
    wave_period_s = _validate.positive("wave_period_s", wave_period_s)
    if not np.isfinite(raise_s) or raise_s < 0:
        raise MocycleError(f"raise_s must be >= 0 seconds; got {raise_s!r}")
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    n_raise = int(round(raise_s * fps))
    p = wave_period_s * fps
    room = n_frames - 2 * n_raise
    if n_waves is None:
        n_wave = room
    else:
        _validate.positive("n_waves", n_waves)
        n_wave = int(round(n_waves * p))
    if n_wave < 2 or n_wave > room:
        raise MocycleError(f"a wave of {n_wave} frames does not fit in {n_frames} frames with {n_raise}-frame "
                           f"raise and lower (or is under 2 frames)")
    s0 = (room - n_wave) // 2
    a, b = s0 + n_raise, s0 + n_raise + n_wave
    e = b + n_raise
    k = np.arange(n_frames, dtype=np.float64)
    if n_raise:
        lift = _smoothstep(np.minimum((k - s0 + 0.5) / n_raise, (e - k - 0.5) / n_raise))
        fade = _smoothstep(np.minimum((k - a + 0.5) / (0.25 * p), (b - k - 0.5) / (0.25 * p)))
    else:
        lift = ((k >= a) & (k < b)).astype(float)
        fade = lift.copy()
    u = (k - a) / p
    swing = 25.0 * fade * np.sin(2.0 * np.pi * u)
    sides = _HANDS[hand]
    ang = _stand_angles(n_frames, fps, {s: lift for s in sides}, {s: swing for s in sides})
    chan = _channels(humanoid_skeleton(), ang)
    if noise_deg > 0:
        chan += _rng(seed).normal(0.0, noise_deg, size=chan.shape)
    skel = humanoid_skeleton()
    root = np.tile([0.0, STAND_HEIGHT, 0.0], (n_frames, 1))
    waving = (k >= a) & (k < b)
    unwrapped = np.where(waving, u, np.nan)
    phase = np.where(waving, unwrapped - np.floor(np.where(waving, unwrapped, 0.0)), np.nan)
    period = np.where(waving, p, np.nan)
    segments = [("stand", 0, s0), ("raise", s0, a), ("wave", a, b), ("lower", b, e), ("stand", e, n_frames)]
    segments = [seg for seg in segments if seg[2] > seg[1]]
    desc = (f"synthetic wave ({hand} hand{'s' if hand == 'both' else ''}): {n_frames} frames at {fps:g} fps, "
            f"wave period {wave_period_s:g} s, {n_wave / p:.2f} waves in frames [{a}, {b}), raise {n_raise} "
            f"frames, noise {noise_deg:g} deg, seed {seed}")
    return SyntheticTake(Motion(skel, _quats_from_channels(skel, chan), None, 1.0 / fps, root_positions=root),
                         phase, unwrapped, period, segments, desc, chan, np.zeros(n_frames))


def synthetic_walk_then_wave(walk_s: float = 4.0, stop_s: float = 0.8, wave_s: float = 4.0, fps: float = 60.0,
                             period_s: float = 1.0, hand: str = "right", wave_period_s: float = 0.6,
                             noise_deg: float = 0.5, seed: int = 0) -> SyntheticTake:
    """A walk that stops and then waves with standing legs, in one take.

    ``walk_s`` seconds of :func:`synthetic_walk` (cycle ``period_s``), then ``stop_s`` seconds in which the
    walk's pose is slerped to the standing pose and the root's horizontal speed eases to zero (its height
    keeping a foot on the floor), then ``wave_s`` seconds of :func:`synthetic_wave` (``hand``,
    ``wave_period_s``, 0.5 s raise and lower) where the walk stopped.  ``noise_deg``: Gaussian noise on
    every rotation channel (degrees).

    Truth: ``segments`` ``[("walk", 0, n_walk), ("transition", ...), ("raise", ...), ("wave", a, b),
    ("lower", ...)]``; :attr:`SyntheticTake.steady_parts` gives the two parts to loop (walk and wave).
    ``period_frames``: the walk's period in the walk, the wave's in the waving, NaN elsewhere;
    ``unwrapped_phase`` counts cycles in the walk and waves (from 0) in the waving; ``heading_deg`` zeros.
    """
    fps = _validate.positive("fps", fps)
    for name, seconds in (("walk_s", walk_s), ("stop_s", stop_s), ("wave_s", wave_s)):
        _validate.positive(name, seconds)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    n_walk, n_stop, n_wave = (max(1, int(round(v * fps))) for v in (walk_s, stop_s, wave_s))
    walk = synthetic_walk(n_walk + n_stop, fps, period_s=period_s)
    wave = synthetic_wave(n_wave, fps, hand=hand, wave_period_s=wave_period_s, raise_s=0.5, noise_deg=0.0)
    assert walk.euler_deg is not None and wave.euler_deg is not None  # both keep their channels
    skel = walk.motion.skeleton
    J = skel.n_joints
    T, _ = _check(n_walk + n_stop + n_wave, fps)
    k = np.arange(T)
    w = _smoothstep((k - n_walk + 0.5) / n_stop)                 # 0 walking, 1 standing
    q_clean = np.concatenate([walk.motion.rotations[:n_walk],
                              np.repeat(wave.motion.rotations[:1], n_stop, axis=0),
                              wave.motion.rotations])
    chan = np.concatenate([walk.euler_deg[:n_walk], np.repeat(wave.euler_deg[:1], n_stop, axis=0),
                           wave.euler_deg])
    inside = np.arange(n_walk, n_walk + n_stop)
    r0 = Rotation.from_quat(walk.motion.rotations[inside].reshape(-1, 4))
    r1 = Rotation.from_quat(np.repeat(wave.motion.rotations[:1], n_stop, axis=0).reshape(-1, 4))
    ww = np.repeat(w[inside], J)[:, None]
    q_clean[inside] = (r0 * Rotation.from_rotvec(ww * (r0.inv() * r1).as_rotvec())).as_quat().reshape(-1, J, 4)
    for j in range(J):
        chan[inside, j] = Rotation.from_quat(q_clean[inside, j]).as_euler(skel.euler_order(j), degrees=True)
    if noise_deg > 0:
        chan = chan + _rng(seed).normal(0.0, noise_deg, size=chan.shape)
        q = _quats_from_channels(skel, chan)
    else:
        q = q_clean
    p0 = walk.motion.root_positions
    v = np.diff(p0, axis=0) * (1.0 - w[1:n_walk + n_stop, None])
    root = np.empty((T, 3))
    root[:n_walk + n_stop] = np.concatenate([p0[:1], p0[:1] + np.cumsum(v, axis=0)])
    root[n_walk + n_stop:] = root[n_walk + n_stop - 1]
    after = np.arange(n_walk, T)
    floor = _floor_height(skel, q_clean[after])
    lift = p0[n_walk:, 1] - _floor_height(skel, walk.motion.rotations[n_walk:])
    lift = np.concatenate([lift, np.zeros(n_wave)])
    root[after, 1] = floor + (1.0 - w[after]) * lift
    root[:n_walk, 1] = p0[:n_walk, 1]
    off = n_walk + n_stop
    period = np.concatenate([walk.period_frames[:n_walk], np.full(n_stop, np.nan), wave.period_frames])
    unwrapped = np.concatenate([walk.unwrapped_phase[:n_walk], np.full(n_stop, np.nan), wave.unwrapped_phase])
    phase = np.concatenate([walk.phase[:n_walk], np.full(n_stop, np.nan), wave.phase])
    segments = [("walk", 0, n_walk), ("transition", n_walk, off)]
    segments += [(lab, a + off, b + off) for lab, a, b in wave.segments]
    desc = (f"synthetic walk then wave ({hand}): walk {n_walk}, stop {n_stop}, wave {n_wave} frames at "
            f"{fps:g} fps, walk period {period_s:g} s, wave period {wave_period_s:g} s, noise {noise_deg:g} deg, "
            f"seed {seed}")
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), phase, unwrapped, period,
                         segments, desc, chan, np.zeros(T))


def synthetic_sway(n_frames: int = 480, fps: float = 60.0, period_s: float = 1.2, noise_deg: float = 0.3,
                   seed: int = 0) -> SyntheticTake:
    """A dance step on the spot: the whole body repeats while the legs move but no foot lands in turn.

    Every ``period_s`` seconds the knees bend and straighten (a bounce, 30 degrees at the knee; the
    trunk nods, the shoulders shrug and the elbows bend with it), the hips roll 6 degrees to one side and back
    to the other, the trunk counters half of it, both arms swing 30 degrees forward and back in turn and the
    trunk turns a little with them; the root goes down with the bounce so that the lower foot stays on the
    floor (no foot lifts more than about 2 % of the body height: no landing, no gait).  ``noise_deg``: Gaussian
    noise on every rotation channel (degrees).

    Truth: ``segments`` ``[("sway", 0, n_frames)]``; ``phase``/``unwrapped_phase`` count periods from frame 0;
    ``period_frames`` ``period_s * fps``; ``heading_deg`` zeros.
    """
    n_frames, fps = _check(n_frames, fps)
    period_s = _validate.positive("period_s", period_s)
    if not np.isfinite(noise_deg) or noise_deg < 0:
        raise MocycleError(f"noise_deg must be >= 0; got {noise_deg!r}")
    u = np.arange(n_frames) / (period_s * fps)
    bounce = 0.5 * (1.0 - np.cos(2.0 * np.pi * u))                  # one bend a period, in [0, 1]
    roll = 6.0 * np.sin(2.0 * np.pi * u)
    swing = np.sin(2.0 * np.pi * u)
    a = np.zeros((n_frames, len(_NAMES), 3))
    a[:, _IX["Hips"], 2] = roll
    a[:, _IX["Spine"], 2] = -0.5 * roll
    for j, share in (("Spine1", 0.3), ("Spine2", 0.3), ("Neck", 0.2), ("Head", 0.2)):  # the trunk and head nod
        a[:, _IX[j], 0] = 8.0 * share * bounce
        a[:, _IX[j], 1] = 10.0 * share * swing                   # and turn a little with the arms
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        a[:, _IX[f"{side}UpLeg"], 0] = -15.0 * bounce
        a[:, _IX[f"{side}UpLeg"], 2] = sign * 2.0 - roll            # the legs stay vertical as the hips roll
        a[:, _IX[f"{side}Leg"], 0] = 30.0 * bounce
        a[:, _IX[f"{side}Foot"], 0] = -15.0 * bounce
        a[:, _IX[f"{side}Shoulder"], 2] = sign * 8.0 * bounce
        a[:, _IX[f"{side}Arm"], 2] = sign * -75.0
        a[:, _IX[f"{side}Arm"], 1] = sign * 30.0 * swing
        a[:, _IX[f"{side}ForeArm"], 1] = -sign * (20.0 + 25.0 * bounce)
        a[:, _IX[f"{side}Hand"], 0] = 15.0 * swing
    skel = humanoid_skeleton()
    chan = _channels(skel, a)
    if noise_deg > 0:
        chan += _rng(seed).normal(0.0, noise_deg, size=chan.shape)
    q = _quats_from_channels(skel, chan)
    root = np.zeros((n_frames, 3))
    root[:, 1] = _floor_height(skel, q)
    unwrapped = u.copy()
    desc = (f"synthetic sway (a dance step on the spot): {n_frames} frames at {fps:g} fps, period {period_s:g} s, "
            f"noise {noise_deg:g} deg, seed {seed}")
    return SyntheticTake(Motion(skel, q, None, 1.0 / fps, root_positions=root), unwrapped % 1.0, unwrapped,
                         np.full(n_frames, period_s * fps), [("sway", 0, n_frames)], desc, chan, np.zeros(n_frames))
