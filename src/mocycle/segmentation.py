"""The records of a swing segmentation (paper 003): :class:`Swing`, :class:`Hold` and :class:`Segmentation`.

What :func:`mocycle.swings.segment` makes, playback, search and editing read, and the swings files hold
(``.mosw``: :mod:`mocycle.io.mosw`; JSON: :mod:`mocycle.io.swings_json`).  Here too are the checks every
reader of them shares (:func:`checked_segmentation`: spans, indices and values, so a damaged file gives one
:class:`~mocycle.errors.MotionFileError` and never a crash in playback) and the plain values of
:meth:`Segmentation.to_dict`.  This module sits below both the swings algorithms and the swings codecs (io),
which import it and not each other; it reads and writes no file format.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from . import defaults
from .motion import Skeleton
from .rotations import axis_angle_quats, quat_multiply, rotvec_quat

#: The paper's box filter and error window: 20 frames at 120 fps, in seconds.
PAPER_WINDOW_S = 20.0 / 120.0
#: The paper's Acceptable Swing Error.
DEFAULT_THRESHOLD = defaults.SWING_THRESHOLD


# ---------------------------------------------------------------- records
def swing_angles(frames, start, end, start_angle, end_angle, start_speed, end_speed, frame_time: float,
                 profile: str = "hermite") -> np.ndarray:
    """``θ`` (radians) of swings at (fractional) ``frames``: the cubic Hermite from ``start_angle`` to
    ``end_angle`` with the end speeds (rad/s), or the paper's linear ramp.  Every argument but
    ``frame_time`` and ``profile`` is a number or an array (broadcast), so many swings go at once."""
    start = np.asarray(start, dtype=np.float64)
    span = np.maximum(np.asarray(end, dtype=np.float64) - start, 1)
    u = np.clip((np.asarray(frames, dtype=np.float64) - start) / span, 0.0, 1.0)
    if profile == "linear":
        return start_angle + (end_angle - start_angle) * u
    dur = span * frame_time
    h00 = 2 * u**3 - 3 * u**2 + 1
    h10 = u**3 - 2 * u**2 + u
    h01 = -2 * u**3 + 3 * u**2
    h11 = u**3 - u**2
    return h00 * start_angle + h10 * dur * start_speed + h01 * end_angle + h11 * dur * end_speed


@dataclass(frozen=True, kw_only=True)
class Swing:
    """One geodesic swing of one joint: ``q(t) = Rot(axis, θ(t)) ⊗ base`` for frames ``start..end``.

    ``start``/``end`` are frame indices (inclusive); ``axis`` a unit vector in the
    parent's frame; ``start_angle``/``end_angle`` radians about ``axis``;
    ``start_speed``/``end_speed`` the angular speed (rad/s) at the ends (the
    cubic Hermite shape of ``θ(t)``); ``base`` the rotation vector (radians) of
    the fixed part ``base``; ``error`` the swing's mean axis error (0-2).
    """

    joint: int
    name: str
    start: int
    end: int
    axis: tuple[float, float, float]
    start_angle: float
    end_angle: float
    start_speed: float = 0.0
    end_speed: float = 0.0
    base: tuple[float, float, float] = (0.0, 0.0, 0.0)
    error: float = 0.0

    @property
    def n_frames(self) -> int:
        return self.end - self.start + 1

    def angles(self, frames: np.ndarray, frame_time: float, profile: str = "hermite") -> np.ndarray:
        """``θ`` (radians) at (fractional) ``frames`` inside the swing: cubic Hermite or the paper's linear."""
        return swing_angles(frames, self.start, self.end, self.start_angle, self.end_angle, self.start_speed,
                            self.end_speed, frame_time, profile)

    def quats(self, frames: np.ndarray, frame_time: float, profile: str = "hermite") -> np.ndarray:
        """Local rotations ``(n, 4)`` (x, y, z, w) of the swing at ``frames``."""
        theta = self.angles(frames, frame_time, profile)
        return quat_multiply(axis_angle_quats(np.asarray(self.axis), theta), rotvec_quat(np.asarray(self.base)))


@dataclass(frozen=True, kw_only=True)
class Hold:
    """A still part of one joint: frames ``start..end`` (inclusive) and their mean rotation (rotation vector, rad)."""

    joint: int
    name: str
    start: int
    end: int
    mean: tuple[float, float, float]

    @property
    def n_frames(self) -> int:
        return self.end - self.start + 1


@dataclass(kw_only=True)
class Segmentation:
    """Swings and holds of every joint of a take, plus what playback needs to rebuild it.

    ``joints`` are the indices that were segmented into swings; every other
    joint is one or more holds.  ``translation_keys`` maps a joint index to
    ``(frames (K,), values (K, 3))``, a piecewise-linear track of its local
    translation (one key when it never changes).
    """

    skeleton: Skeleton
    n_frames: int
    frame_time: float
    joints: list[int]
    swings: list[Swing]
    holds: list[Hold]
    translation_keys: dict[int, tuple[np.ndarray, np.ndarray]]
    threshold: float = DEFAULT_THRESHOLD
    window_s: float = PAPER_WINDOW_S
    params: dict = field(default_factory=dict)

    @property
    def n_swings(self) -> int:
        return len(self.swings)

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    def swings_of(self, joint: int | str) -> list[Swing]:
        """The swings of one joint in time order."""
        j = self.skeleton.index(joint) if isinstance(joint, str) else int(joint)
        return sorted((s for s in self.swings if s.joint == j), key=lambda s: s.start)

    def holds_of(self, joint: int | str) -> list[Hold]:
        j = self.skeleton.index(joint) if isinstance(joint, str) else int(joint)
        return sorted((h for h in self.holds if h.joint == j), key=lambda h: h.start)

    def to_records(self) -> list[dict]:
        """One flat dict per swing and hold (``kind``, ``joint``, frames, seconds, axis, angles in degrees)."""
        dt = self.frame_time
        rows = []
        for s in sorted(self.swings, key=lambda s: (s.joint, s.start)):
            rows.append(dict(kind="swing", joint=s.name, start=s.start, end=s.end, start_s=s.start * dt,
                             end_s=s.end * dt, axis_x=s.axis[0], axis_y=s.axis[1], axis_z=s.axis[2],
                             start_angle_deg=float(np.degrees(s.start_angle)),
                             end_angle_deg=float(np.degrees(s.end_angle)),
                             start_speed_deg_s=float(np.degrees(s.start_speed)),
                             end_speed_deg_s=float(np.degrees(s.end_speed)), error=s.error))
        for h in sorted(self.holds, key=lambda h: (h.joint, h.start)):
            rows.append(dict(kind="hold", joint=h.name, start=h.start, end=h.end, start_s=h.start * dt,
                             end_s=h.end * dt, mean_rotvec=list(h.mean)))
        return rows

    def to_dict(self) -> dict:
        """Everything but the skeleton as JSON-ready values (the swings JSON document adds the skeleton:
        :func:`mocycle.io.swings_json.swings_document`)."""
        return dict(
            frames=self.n_frames, frame_time=self.frame_time, fps=self.fps, threshold=self.threshold,
            window_s=self.window_s, params=dict(self.params),
            joints=[self.skeleton.names[j] for j in self.joints], n_swings=self.n_swings,
            swings=[asdict(s) for s in sorted(self.swings, key=lambda s: (s.joint, s.start))],
            holds=[asdict(h) for h in sorted(self.holds, key=lambda h: (h.joint, h.start))],
            translation_keys={str(j): dict(frames=f.tolist(), values=v.tolist())
                              for j, (f, v) in self.translation_keys.items()},
        )


# ---------------------------------------------------------------- reading back, checked
#: The longest skeleton text a swings file may hold (about 100k joints).
MAX_SKELETON_BYTES = 64 * 2**20

def checked_segmentation(error, skel: Skeleton, T: int, frame_time: float, threshold: float, window_s: float,
                         joints: list[int], swings: dict, holds: dict, keys: dict,
                         params: dict | None = None) -> Segmentation:
    """A :class:`Segmentation` from columns read out of a file, after checking every index, span and value.

    ``error(reason)`` makes the :class:`MotionFileError` naming the file.  ``swings``: ``joint``, ``start``,
    ``end`` ``(n,)`` int64, ``axis`` and ``base`` ``(n, 3)``, ``start_angle``, ``end_angle``, ``start_speed``,
    ``end_speed``, ``error`` ``(n,)``; ``holds``: ``joint``, ``start``, ``end`` ``(m,)`` int64, ``mean``
    ``(m, 3)``; ``keys``: joint -> (frames ``(k,)`` int64, values ``(k, 3)``).  Shared by the ``.mosw`` and
    the JSON readers, so a damaged file of either gives one error and never a crash in playback.
    """
    J = skel.n_joints
    sj, ss, se = swings["joint"], swings["start"], swings["end"]
    hj, hs, he = holds["joint"], holds["start"], holds["end"]
    _check_events(error, "swing", sj, ss, se - ss, T, J, min_length=1)
    _check_events(error, "hold", hj, hs, he - hs, T, J, min_length=0)
    _check_cover(error, np.concatenate([sj, hj]), np.concatenate([ss, hs]), np.concatenate([se, he]), T)
    if len(set(joints)) != len(joints) or any(j >= J or j < 0 for j in joints):
        raise error(f"its segmented joints repeat or exceed the skeleton's {J} joints")
    for name in ("axis", "start_angle", "end_angle", "start_speed", "end_speed", "base", "error"):
        v = swings[name]
        if not np.all(np.isfinite(v)) or (v.size and np.abs(v).max() > MAX_VALUE):
            raise error(f"a swing's {name.replace('_', ' ')} is not a finite number within ±{MAX_VALUE:g}")
    norms = np.linalg.norm(swings["axis"], axis=1)
    if np.any(np.abs(norms - 1.0) > 1e-3):
        raise error("a swing's axis is not a unit vector")
    axis = np.where(np.abs(norms - 1.0)[:, None] > 1e-12, swings["axis"] / norms[:, None], swings["axis"])
    hm = holds["mean"]
    if not np.all(np.isfinite(hm)) or (hm.size and np.abs(hm).max() > MAX_VALUE):
        raise error(f"a hold's mean rotation is not a finite rotation vector within ±{MAX_VALUE:g}")
    tj = np.array(sorted(keys), dtype=np.int64)
    if np.any(tj >= J) or np.any(tj < 0):
        raise error(f"its translated joints must be joint numbers below {J}")
    for j, (f, v) in keys.items():
        if f.size == 0 or v.shape != (f.size, 3):
            raise error(f"joint {j}'s translation keys: {f.size} frames but {v.size} values")
        if f[0] != 0 or f[-1] >= T or np.any(np.diff(f) <= 0) or (f.size > 1 and f[-1] != T - 1):
            raise error(f"joint {j}'s translation key frames must increase from 0 (to {T - 1} when they move)")
        if not np.all(np.isfinite(v)) or np.abs(v).max() > MAX_VALUE:
            raise error(f"joint {j}'s translation values are not finite numbers within ±{MAX_VALUE:g}")
    names = skel.names
    out_swings = [Swing(joint=int(sj[i]), name=names[sj[i]], start=int(ss[i]), end=int(se[i]),
                        axis=_vec3(axis[i]), start_angle=float(swings["start_angle"][i]),
                        end_angle=float(swings["end_angle"][i]), start_speed=float(swings["start_speed"][i]),
                        end_speed=float(swings["end_speed"][i]), base=_vec3(swings["base"][i]),
                        error=float(swings["error"][i])) for i in range(sj.size)]
    out_holds = [Hold(joint=int(hj[i]), name=names[hj[i]], start=int(hs[i]), end=int(he[i]),
                      mean=_vec3(hm[i])) for i in range(hj.size)]
    return Segmentation(skeleton=skel, n_frames=T, frame_time=frame_time, joints=list(joints), swings=out_swings,
                        holds=out_holds, translation_keys=keys, threshold=threshold, window_s=window_s,
                        params=dict(params or {}))


def _vec3(v) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])


#: The largest translation a swings file may hold (file units): far above any take, far below overflow.
MAX_VALUE = 1e12


def _check_cover(error, joint: np.ndarray, start: np.ndarray, end: np.ndarray, T: int) -> None:
    """The swings and holds of every joint that has any run from frame 0 to the last frame (what
    :func:`~mocycle.swings.segment` writes): a frame count that no record reaches is damage."""
    if not joint.size:
        return
    first = np.full(joint.max() + 1, T, dtype=np.int64)
    last = np.full(joint.max() + 1, -1, dtype=np.int64)
    np.minimum.at(first, joint, start)
    np.maximum.at(last, joint, end)
    used = np.unique(joint)
    if np.any(first[used] != 0) or np.any(last[used] != T - 1):
        raise error(f"its swings and holds do not span the take's {T} frames (from 0 to {T - 1})")


def _check_events(error, what: str, joint, start, length, T: int, J: int, min_length: int) -> None:
    """Swings or holds: joints below ``J``, sorted by (joint, start), inside the take, not overlapping
    (a swing may start on the frame the one before it ends)."""
    if not joint.size:
        return
    j = joint.astype(np.int64)
    s = start.astype(np.int64)
    e = s + length.astype(np.int64)
    if j.max() >= J:
        raise error(f"a {what} names joint {int(j.max())}; the skeleton has {J}")
    if np.any(j < 0) or np.any(s < 0) or np.any(length < min_length) or e.max() >= T:
        raise error(f"a {what} lies outside the take's {T} frames or is shorter than {min_length} frame(s)")
    same = j[1:] == j[:-1]
    if np.any(j[1:] < j[:-1]) or np.any(same & (s[1:] < e[:-1])):
        raise error(f"its {what}s are not in time order per joint or overlap")
