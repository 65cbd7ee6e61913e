"""Pose features: a :class:`~mocycle.motion.Motion` as a matrix X (T×D) and back.

``pose_matrix`` is the one way from a motion to numbers for every algorithm;
its decoder is the one way back, so anything an algorithm makes (a cycle, a
blend, a reconstruction) returns to a Motion and to a BVH file the same way.

Representations of the joint rotations (``rep``):

``euler``     the joint's own Euler angles (radians), unwrapped in time
``expmap``    rotation vector (axis × angle, radians), continuous in time
``quatlog``   quaternion logarithm of ``ref⁻¹·q`` about a reference pose
              (θ/2 · axis; the reference defaults to each joint's mean rotation)
``rotmat``    the 9 entries of the rotation matrix (decoding projects back to
              the nearest rotation)

Root translation (``root_features``; not a loop's ``root``, which says whether the written loop travels):
``keep`` (positions), ``velocity`` (first
differences per frame; row 0 repeats row 1), ``heading`` or ``drop``.
``heading`` is paper 001 §4.1 in full: root position *and orientation* as
first differences, so nothing depends on where the actor faces.  The root's
rotation is split into its heading about the vertical axis and its tilt
(:class:`~mocycle.cycle.representation.CycleSpace` finds the vertical, Y-up
or Z-up); the tilt replaces the root's rotation columns, and four columns
follow: the root velocity in the root's own heading frame (3, file units per
frame) and the heading rate (1, radians per frame).  A walk along a circle
then gives the same features as a straight one.
"Root" means ``motion.travel_joint``: the root, or the first joint whose
translation moves when the root is static (Bandai files move ``Hips``).

Optional per-DOF normalisation (z-score) and per-joint weights, e.g. the bone
lengths of the KTH thesis, chapter 4: ``X = (raw - mean) / std * weight``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from . import _validate
from .axes import heading_angles, horizontal_basis, up_in_parent_frame, vertical_axis
from .errors import MocycleError, OptionError
from .motion import Motion
from .rotations import (
    axis_angle_quats,
    continuous_euler,
    continuous_rotvec,
    euler_to_quats,
    matrix_quats,
    mean_rotations,
    nearest_rotations,
    quat_conj,
    quat_exp,
    quat_multiply,
)

REPS = ("euler", "expmap", "quatlog", "rotmat")
ROOT_FEATURES = ("keep", "velocity", "heading", "drop")
ROOTS = ROOT_FEATURES  # the old name
#: frames decoded at a time by :meth:`PoseDecoder.decode_arrays` (its temporaries stay a block's size)
DECODE_BLOCK = 8192
_AXES = ("x", "y", "z")


@dataclass(frozen=True, eq=False, kw_only=True)
class PoseDecoder:
    """Turns pose matrices made by :func:`pose_matrix` back into motions.

    Attributes
    ----------
    template : the motion that was encoded; joints that are not features
        (unselected joints, non-root translations, a dropped root) come from it.
    rep, root_features : the representation and root handling used.
    joints : indices of the joints whose rotations are columns.
    columns : a name per column, e.g. ``"LeftUpLeg:rx"``, ``"root:vz"``.
    dof_joint : ``(D,)`` joint index per column (root translation columns: 0).
    mean, scale : ``(D,)``: ``X = (raw - mean) / scale``.
    reference : ``(J, 4)`` reference quaternions of the ``quatlog`` rep.
    travel : the joint whose translation the root columns hold.
    frame : with ``root_features="heading"``, the :class:`HeadingFrame` used.
    """

    template: Motion
    rep: str
    root_features: str
    joints: tuple[int, ...]
    columns: tuple[str, ...]
    dof_joint: np.ndarray
    mean: np.ndarray
    scale: np.ndarray
    reference: np.ndarray
    travel: int = 0
    frame: HeadingFrame | None = None

    @property
    def n_features(self) -> int:
        return len(self.columns)

    def encode(self, motion: Motion) -> np.ndarray:
        """The pose matrix of another motion with the same skeleton, same transform."""
        if not motion.skeleton.same_as(self.template.skeleton):
            raise MocycleError("cannot encode a motion whose skeleton differs from the template's")
        raw = _raw_features(motion, self.rep, self.root_features, self.joints, self.reference, self.travel, self.frame)
        return (raw - self.mean) / self.scale

    def decode(self, X: np.ndarray, frame_time: float | None = None) -> Motion:
        """A :class:`Motion` from ``X`` (``(T, D)``; T may differ from the template's).

        Non-feature parts come from the template frame by frame when T matches,
        otherwise from its mean pose (rotations) and first frame (root).
        """
        quats, translations = self.decode_arrays(X)
        assert translations is not None  # asked for (translations=True)
        static, tracks = translations
        tpl = self.template
        return Motion(tpl.skeleton, quats, static, tpl.frame_time if frame_time is None else frame_time,
                      tracks=tracks, copy=False)  # decode_arrays made them: handed over, not copied

    def decode_arrays(self, X: np.ndarray, translations: bool = True) -> tuple[np.ndarray, tuple | None]:
        """What :meth:`decode` makes a motion of: quaternions ``(T, J, 4)`` (not yet normalised) and the
        translations as a motion stores them, constant ``(J, 3)`` and ``{joint: (T, 3)}`` tracks (``None`` with
        ``translations=False``, for a caller that has its own)."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.n_features:
            raise MocycleError(f"X must have shape (T, {self.n_features}); got {X.shape}")
        if not np.all(np.isfinite(X)):
            raise MocycleError("X contains NaN or infinite values")

        def raw(c0: int, c1: int, rows: slice = slice(None)) -> np.ndarray:
            """Columns ``c0:c1`` of the features before normalising (a block of them: no ``(T, D)`` copy)."""
            return X[rows, c0:c1] * self.scale[c0:c1] + self.mean[c0:c1]

        tpl = self.template
        T, J = X.shape[0], tpl.n_joints
        same_length = T == tpl.n_frames
        kept = np.setdiff1d(np.arange(J), self.joints)  # joints whose rotations are not columns
        if same_length:
            quats = tpl.rotations.copy()
            static, tracks = tpl.translations_at(0), tpl.tracks
        else:
            quats = np.empty((T, J, 4))
            if kept.size:
                quats[:, kept] = mean_rotations(tpl.rotations[:, kept])
            static = np.stack([tpl.joint_translations(j).mean(axis=0) for j in range(J)])  # the mean pose
            static[self.travel] = tpl.joint_translations(self.travel)[0]
            tracks = {}
        col = 0
        skel = tpl.skeleton
        if self.root_features == "heading":  # the travel joint's columns hold its tilt: start from the template's
            assert self.frame is not None  # pose_matrix gives root_features="heading" its frame
            tilt = self.frame.tilt(tpl)[0]
            quats[:, self.travel] = tilt if same_length else Rotation.from_quat(tilt).mean().as_quat()
        if self.rep == "euler":
            for order, joints in _joints_by_order(skel, self.joints).items():
                k = len(order)
                block = np.stack([raw(col + i * k, col + (i + 1) * k) for i in range(len(joints))], 1)
                quats[:, joints] = euler_to_quats(block, order)
                col += k * len(joints)
        else:
            n = len(self.joints)
            width = 9 if self.rep == "rotmat" else 3
            js = list(self.joints)
            ref = self.reference[js] / np.linalg.norm(self.reference[js], axis=-1, keepdims=True)
            for f0 in range(0, T, DECODE_BLOCK):  # blocks of frames: every frame is decoded on its own
                rows = slice(f0, min(f0 + DECODE_BLOCK, T))
                block = raw(col, col + width * n, rows).reshape(-1, n, width)
                if self.rep == "expmap":
                    quats[rows, js] = quat_exp(block)
                elif self.rep == "quatlog":
                    quats[rows, js] = quat_multiply(ref, quat_exp(2.0 * block))
                else:
                    quats[rows, js] = matrix_quats(nearest_rotations(block.reshape(-1, n, 3, 3)))
            col += width * n
        start = tpl.joint_translations(self.travel)[0]
        if self.root_features == "keep" and translations:
            tracks[self.travel] = raw(col, col + 3)
        elif self.root_features == "velocity" and translations:
            v = raw(col, col + 3)
            tracks[self.travel] = start + np.concatenate([np.zeros((1, 3)), np.cumsum(v[1:], axis=0)])
        elif self.root_features == "heading":
            assert self.frame is not None  # pose_matrix gives root_features="heading" its frame
            _, psi = self.frame.tilt(tpl[:1])
            psi = psi[0] + np.concatenate([[0.0], np.cumsum(raw(col + 3, col + 4, slice(1, None))[:, 0])])
            quats[:, self.travel] = self.frame.turn(quats[:, self.travel], psi)
            if translations:
                v = self.frame.to_world(raw(col, col + 3, slice(1, None)), 0.5 * (psi[1:] + psi[:-1]))
                tracks[self.travel] = start + np.concatenate([np.zeros((1, 3)), np.cumsum(v, axis=0)])
        return quats, (static, tracks) if translations else None


@dataclass(frozen=True, eq=False)
class HeadingFrame:
    """The travel joint's heading about the vertical and the frame it defines (``root_features="heading"``).

    ``up``: the vertical axis ``(3,)`` in the travel joint's parent frame; ``e1``, ``e2``: a horizontal
    basis there; ``forward``: the vector in the travel joint's own frame whose horizontal direction is the
    heading (``up``, ``e1``, ``e2`` from :mod:`mocycle.axes`, as :class:`~mocycle.cycle.representation.CycleSpace`
    finds them; ``forward`` perpendicular to the joint's mean local up, so it does not depend on the headings).
    """

    travel: int
    up: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    forward: np.ndarray

    @classmethod
    def fit(cls, motion: Motion) -> HeadingFrame:
        """The frame of ``motion``, fitted once per motion (its arrays are read-only), as its :meth:`tilt`."""
        return motion.cache("heading", cls._fit)

    @classmethod
    def _fit(cls, motion: Motion) -> HeadingFrame:
        travel = motion.travel_joint
        up = up_in_parent_frame(motion, travel, vertical_axis(motion))  # the one detection (Y-up, Z-up rigs)
        e1, e2 = horizontal_basis(up)
        # Forward: perpendicular to the joint's mean *local* up direction (R^T up does not change when
        # the walker turns about up), so the tilt is the same whichever way the take faces.
        R = Rotation.from_quat(motion.rotations[:: max(1, motion.n_frames // 200), travel])
        local_up = R.inv().apply(up).mean(axis=0)
        if not np.linalg.norm(local_up) > 1e-9:  # as the cycle space's forward
            return cls(travel, up, e1, e2, motion.rotation(travel).mean().as_matrix().T @ e1)
        forward, _ = horizontal_basis(local_up / np.linalg.norm(local_up))
        return cls(travel, up, e1, e2, forward)

    def _about_up(self, v: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Vectors ``(N, 3)`` turned by ``angles`` ``(N,)`` rad about ``up`` (Rodrigues' formula)."""
        v = np.asarray(v, dtype=np.float64)
        u = self.up
        c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
        cross = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])  # u × v = cross @ v
        return v * c + (v @ cross.T) * s + (v @ u)[:, None] * u * (1.0 - c)

    def tilt(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        """The travel joint's rotation without its heading ``(T, 4)`` and the unwrapped heading ``(T,)`` rad
        (read-only arrays: computed once per motion and frame, as the phase's features and its leg curves
        both need them)."""
        if motion.cache("heading") is not self:  # a frame fitted on another motion: nothing to keep
            return self._tilt(motion)
        return motion.cache("heading tilt", self._tilt)

    def _tilt(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        q = motion.rotations[:, self.travel]
        psi = heading_angles(Rotation.from_quat(q).apply(self.forward), self.e1, self.e2)
        tilt = quat_multiply(axis_angle_quats(self.up, -psi), q)
        tilt.setflags(write=False)
        psi.setflags(write=False)
        return tilt, psi

    def turn(self, quats: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Tilt quaternions ``(T, 4)`` turned to the headings ``angles`` ``(T,)`` rad."""
        q = np.asarray(quats, dtype=np.float64)
        return quat_multiply(axis_angle_quats(self.up, angles), q / np.linalg.norm(q, axis=-1, keepdims=True))

    def to_local(self, v: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Vectors ``(T, 3)`` of the parent frame in the heading frames at ``angles`` ``(T,)``."""
        return self._about_up(v, -np.asarray(angles, dtype=np.float64))

    def to_world(self, v: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`to_local`."""
        return self._about_up(v, np.asarray(angles, dtype=np.float64))


def _joints_by_order(skel, joints: Iterable[int]) -> dict[str, list[int]]:
    groups: dict[str, list[int]] = {}
    for j in joints:
        groups.setdefault(skel.euler_order(j), []).append(j)
    return groups


#: rows per block of :func:`column_sums_of_squares`
SQUARES_BLOCK = 8192


def column_sums_of_squares(X: np.ndarray) -> np.ndarray:
    """``np.add.reduce(np.square(X), axis=0)`` ``(D,)`` of ``X`` ``(T, D)`` without the ``(T, D)`` squares: a
    block of rows at a time, each block's squared rows added on to the running sums in order.  numpy adds the
    rows of a C-ordered array one after the other along axis 0, so these are the same bits; a single column
    (which numpy sums pairwise) or a short or non-C-ordered array is summed at once."""
    T, D = X.shape
    if D < 2 or T <= SQUARES_BLOCK or not X.flags.c_contiguous:
        return np.add.reduce(np.square(X), axis=0)
    sums = np.add.reduce(np.square(X[:SQUARES_BLOCK]), axis=0)
    rows = np.empty((SQUARES_BLOCK + 1, D))
    for f0 in range(SQUARES_BLOCK, T, SQUARES_BLOCK):
        block = X[f0:f0 + SQUARES_BLOCK]
        n = block.shape[0]
        rows[0] = sums  # the sums so far, then this block's rows: added in the same order as the whole array
        np.square(block, out=rows[1:n + 1])
        sums = np.add.reduce(rows[:n + 1], axis=0)
    return sums


def _raw_features(motion: Motion, rep: str, root_features: str, joints: tuple[int, ...],
                  reference: np.ndarray, travel: int, frame: HeadingFrame | None = None) -> np.ndarray:
    T = motion.n_frames
    js = list(joints)
    parts = []
    out = None  # the feature matrix, when a part is written straight into it
    tilt = None
    if root_features == "heading":
        assert frame is not None  # pose_matrix gives root_features="heading" its frame
        tilt, psi = frame.tilt(motion)

    def rotations(group: list[int]) -> np.ndarray:
        """``(T, len(group), 4)``: the joints' rotations, the travel joint's tilt in place of its own."""
        q = motion.rotations[:, group]
        if tilt is not None and travel in group:
            q[:, group.index(travel)] = tilt
        return q

    if rep == "euler":
        for order, group in _joints_by_order(motion.skeleton, js).items():
            parts.append(continuous_euler(rotations(group), order).reshape(T, -1))
    elif rep == "expmap":
        if js == list(range(motion.n_joints)):  # every joint: no (T, J, 4) copy; each joint's curve is its own
            # written straight into the feature matrix: no (T, 3J) part joined to the root's afterwards
            out = np.empty((T, len(_columns(motion, rep, root_features, joints)[0])))
            v = continuous_rotvec(motion.rotations, out=out[:, :3 * len(js)].reshape(T, len(js), 3))
            if tilt is not None:
                v[:, travel] = continuous_rotvec(tilt[:, None])[:, 0]
        else:
            v = continuous_rotvec(rotations(js))
        parts.append(v.reshape(T, -1))
    elif rep == "quatlog":
        ref = reference[js] / np.linalg.norm(reference[js], axis=-1, keepdims=True)
        rel = quat_multiply(quat_conj(ref), rotations(js))
        parts.append(0.5 * continuous_rotvec(rel).reshape(T, -1))
    else:
        parts.append(Rotation.from_quat(rotations(js).reshape(-1, 4)).as_matrix().reshape(T, -1))
    if root_features == "keep":
        parts.append(motion.joint_translations(travel))
    elif root_features == "velocity":
        p = motion.joint_translations(travel)
        v = np.diff(p, axis=0) if T > 1 else np.zeros((1, 3))
        parts.append(np.concatenate([v[:1], v]) if T > 1 else v)
    elif root_features == "heading":
        assert frame is not None  # as above
        if T > 1:
            mid = 0.5 * (psi[1:] + psi[:-1])
            v = np.c_[frame.to_local(np.diff(motion.joint_translations(travel), axis=0), mid), np.diff(psi)]
            v = np.concatenate([v[:1], v])
        else:
            v = np.zeros((1, 4))
        parts.append(v)
    if out is not None:  # parts[0] is out's first columns already
        c = parts[0].shape[1]
        for part in parts[1:]:
            out[:, c:c + part.shape[1]] = part
            c += part.shape[1]
        if c != out.shape[1]:  # pragma: no cover - _columns and the parts disagree
            raise MocycleError(f"internal: {c} feature columns made, {out.shape[1]} named")
        return out
    return np.concatenate(parts, axis=1) if parts else np.zeros((T, 0))


def _columns(motion: Motion, rep: str, root_features: str, joints) -> tuple[list[str], list[int]]:
    skel = motion.skeleton
    names: list[str] = []
    owner: list[int] = []
    if rep == "euler":
        for order, group in _joints_by_order(skel, joints).items():
            for j in group:
                names += [f"{skel.names[j]}:r{a.lower()}" for a in order]
                owner += [j] * len(order)
    else:
        labels = [f"m{r}{c}" for r in range(3) for c in range(3)] if rep == "rotmat" else (
            ["rx", "ry", "rz"] if rep == "expmap" else ["qx", "qy", "qz"])
        for j in joints:
            names += [f"{skel.names[j]}:{lab}" for lab in labels]
            owner += [j] * len(labels)
    if root_features == "heading":  # velocity in the heading frame, heading rate
        names += [f"root:h{a}" for a in _AXES] + ["root:dheading"]
        owner += [0, 0, 0, 0]
    elif root_features != "drop":
        prefix = "v" if root_features == "velocity" else ""
        names += [f"root:{prefix}{a}" for a in _AXES]
        owner += [0, 0, 0]
    return names, owner


def _joint_weights(motion: Motion, weights, joints) -> np.ndarray:
    """Per-joint weights ``(J,)`` from None, ``"bone"``, a mapping or an array."""
    skel = motion.skeleton
    J = skel.n_joints
    if weights is None:
        return np.ones(J)
    if isinstance(weights, str):
        if weights != "bone":
            raise MocycleError(f"weights must be None, 'bone', a mapping or an array; got {weights!r}")
        lengths = skel.bone_lengths()
        top = lengths[list(joints)].max() if len(joints) else 0.0
        if top <= 0:
            return np.ones(J)
        w = lengths / top
        w[0] = 1.0  # the root (its translation) weighs like the longest bone
        return np.maximum(w, 1e-3)
    if isinstance(weights, Mapping):
        w = np.ones(J)
        for name, value in weights.items():
            w[skel.index(name)] = float(value)
    else:
        w = np.asarray(weights, dtype=np.float64)
        if w.shape != (J,):
            raise MocycleError(f"weights must have one value per joint ({J}); got shape {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise OptionError("weights", f"must be positive finite numbers, one per joint; got {w.tolist()}")
    return w


def pose_matrix(
    motion: Motion,
    rep: str = "expmap",
    root_features: str = "velocity",
    joints: str | Iterable[str] | None = None,
    weights: str | Mapping[str, float] | np.ndarray | None = None,
    normalize: bool = False,
    reference: Motion | np.ndarray | None = None,
    *,
    root: str | None = None,
) -> tuple[np.ndarray, PoseDecoder]:
    """The pose matrix X (T×D) of ``motion`` and a decoder back to a Motion.

    Parameters
    ----------
    rep : ``"euler"``, ``"expmap"``, ``"quatlog"`` or ``"rotmat"`` (module notes).
    root_features : ``"keep"``, ``"velocity"``, ``"heading"`` or ``"drop"``: how the root enters the features
        (module notes); ``root`` is its old name, accepted with a DeprecationWarning until the next release.
    joints : joint names, glob patterns or group names (``"legs"``, ``"arms"``,
        ``"spine"``), a comma-separated string or a list; ``None``: every joint
        with rotation channels.
    weights : ``None``, ``"bone"`` (bone-length weights, KTH thesis ch. 4),
        ``{joint name: weight}`` or a ``(J,)`` array; multiplies the joint's columns.
    normalize : z-score every column (constant columns keep scale 1).
    reference : the ``quatlog`` reference pose: a motion (its frame 0) or
        ``(J, 4)`` quaternions; default each joint's mean rotation.

    Returns
    -------
    X : ``(T, D)`` float array.
    decoder : :class:`PoseDecoder` (``decoder.decode(X)`` gives the motion back).

    Examples
    --------
    >>> import numpy as np
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60).motion
    >>> X, decoder = pose_matrix(walk, rep="expmap", root_features="velocity", joints="legs")
    >>> X.shape, decoder.columns[:2]
    ((300, 27), ('LeftUpLeg:rx', 'LeftUpLeg:ry'))
    >>> back = decoder.decode(X)                   # the motion again
    >>> bool(np.allclose(back.rotations, walk.rotations))
    True
    """
    _validate.choice("rep", rep, REPS)
    root_features = _validate.renamed("root", "root_features", root, root_features, "velocity")
    _validate.choice("root_features", root_features, ROOT_FEATURES)
    if not isinstance(motion, Motion):
        raise MocycleError(f"pose_matrix needs a Motion; got {type(motion).__name__}")
    skel = motion.skeleton
    selected = skel.select(joints)
    chosen = tuple(j for j in selected if skel.euler_order(j))
    if not chosen and root_features == "drop":
        raise MocycleError("no features: the selected joints have no rotation channels and the root is dropped")
    travel = motion.travel_joint
    frame = HeadingFrame.fit(motion) if root_features == "heading" else None
    if rep == "quatlog":
        if reference is None:
            ref = mean_rotations(motion.rotations)
            if frame is not None:  # the travel joint's columns are its tilt: about the mean tilt
                ref[travel] = mean_rotations(frame.tilt(motion)[0][:, None])[0]
        elif isinstance(reference, Motion):
            ref = reference.rotations[0]
        else:
            ref = np.asarray(reference, dtype=np.float64)
            if ref.shape != (skel.n_joints, 4):
                raise MocycleError(f"reference must be a Motion or ({skel.n_joints}, 4) quaternions")
    else:
        ref = np.tile([0.0, 0.0, 0.0, 1.0], (skel.n_joints, 1))
    raw = _raw_features(motion, rep, root_features, chosen, ref, travel, frame)
    columns, owner = _columns(motion, rep, root_features, chosen)
    owner_arr = np.asarray(owner, dtype=np.int64)
    D = raw.shape[1]
    mean = np.zeros(D)
    scale = np.ones(D)
    centred = raw
    if normalize:
        mean = raw.mean(axis=0)
        centred = np.subtract(raw, mean, out=raw)  # in place: raw is not read again (a (T, D) array less)
        # raw.std(axis=0) from the centred rows numpy's _var makes anyway (the same operations, the same bits)
        std = np.sqrt(column_sums_of_squares(centred) / raw.shape[0])
        scale = np.where(std > 1e-12 * (1.0 + np.abs(mean)), std, 1.0)
    w = _joint_weights(motion, weights, chosen)
    scale = scale / w[owner_arr]
    X = np.divide(centred, scale, out=centred if normalize else None)
    decoder = PoseDecoder(template=motion, rep=rep, root_features=root_features, joints=chosen, columns=tuple(columns),
                          dof_joint=owner_arr, mean=mean, scale=scale, reference=ref, travel=travel,
                          frame=frame)
    return X, decoder


def delay_embed(X: np.ndarray, m: int, step: int = 1) -> np.ndarray:
    """Delay embedding of the KTH thesis eq. 3.26.

    Row i of the result is ``(x_i, x_{i+step}, ..., x_{i+m*step})``; shape
    ``(T - m*step, D*(m+1))``.  Row i belongs to frame i; the first D columns
    are X itself.  ``m = 0`` returns X.
    """
    X = np.asarray(X)
    if X.ndim != 2:
        raise MocycleError(f"X must be a 2-D array (T, D); got shape {X.shape}")
    m, step = int(m), int(step)
    if m < 0 or step < 1:
        raise MocycleError(f"delay embedding needs m >= 0 and step >= 1; got m={m}, step={step}")
    T = X.shape[0]
    n = T - m * step
    if n < 1:
        raise MocycleError(f"delay embedding with m={m}, step={step} needs more than {m * step} frames; got {T}")
    return np.concatenate([X[k * step: k * step + n] for k in range(m + 1)], axis=1)
