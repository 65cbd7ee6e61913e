"""Acclaim ASF/AMC reader (the format of the CMU motion capture database).

An ``.asf`` file holds the skeleton: per bone a direction, a length, an
``axis`` frame and its degrees of freedom, plus the ``:hierarchy``.  An
``.amc`` file holds the dof values frame by frame.  The pair becomes a
:class:`~mocycle.motion.Motion` the way the CMU amc viewers and the CMU BVH
conversions do it:

* joint 0 is ``root``, then one joint per bone in depth-first order of the
  ``:hierarchy`` (children in the order listed).  A bone's joint sits at the
  bone's start, i.e. at its parent's end; every leaf bone gets an End Site at
  its own end.  Root channels: ``Xposition Yposition Zposition Zrotation
  Yrotation Xrotation``; every other joint: ``Zrotation Yrotation Xrotation``.
* the local rotation of a bone is ``C · M · C⁻¹``: ``C`` from the bone's
  ``axis a b c ORDER`` line, ``M`` from its dof values, both built as rotations
  about fixed (extrinsic) axes applied in the order listed
  (``axis a b c XYZ`` -> ``Rz(c) Ry(b) Rx(a)``).
* lengths stay in file units; the ``:units length`` scale is only recorded in
  :attr:`AsfSkeleton.units`.

Every problem with the input raises :class:`~mocycle.errors.MotionFileError`
naming the file, the line and what was expected.
"""

from __future__ import annotations

import math
import os
import warnings
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate, defaults
from ..errors import MocycleError, MocycleWarning, MotionFileError
from ..limits import MAX_MAGNITUDE, frame_time_problem
from ..motion import EndSite, Motion, Skeleton

__all__ = ["AsfSkeleton", "parse_amc", "parse_asf", "read_amc", "read_asf", "read_asfamc"]

#: Frame rate of AMC files, which do not store it (CMU captured at 120 fps).
AMC_FPS = defaults.AMC_FPS

ROOT = "root"
ROOT_CHANNELS = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
BONE_CHANNELS = ("Zrotation", "Yrotation", "Xrotation")
_ROOT_ORDER_TOKENS = ("TX", "TY", "TZ", "RX", "RY", "RZ")
_ROTATION_DOFS = ("rx", "ry", "rz")
_TRANSLATION_DOFS = ("tx", "ty", "tz", "l")
_ANGLE_UNITS = {"deg": "deg", "degree": "deg", "degrees": "deg",
                "rad": "rad", "radian": "rad", "radians": "rad"}
# The Acclaim spec treats commas and parentheses as white space.
_ASF_SEPARATORS = str.maketrans({",": " ", "(": " ", ")": " "})


# --------------------------------------------------------------------------
# the ASF skeleton
# --------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class AsfSkeleton:
    """An ASF skeleton as written in the file, bones in depth-first hierarchy order.

    Bone ``i`` becomes joint ``i + 1`` of :meth:`to_skeleton` (joint 0 is the root).

    Attributes
    ----------
    bones : bone names, ``N`` strings, in depth-first order of ``:hierarchy``.
    parents : parent bone name per bone (``"root"`` for the root's children).
    directions : ``(N, 3)`` unit direction of each bone in world axes.
    lengths : ``(N,)`` bone lengths in file length units (not scaled).
    axes : ``(N, 3)`` the ``axis`` angles, in the file's angle unit.
    axis_orders : per bone the ``axis`` order string, e.g. ``"XYZ"``.
    dofs : per bone its rotation dofs in file order, e.g. ``("rx", "rz")``.
    limits : per bone the ``(min, max)`` pairs of its ``limits`` line (may be empty).
    root_order : the root ``order`` tokens, e.g. ``("TX", "TY", "TZ", "RX", "RY", "RZ")``.
    root_axis : the root ``axis`` order string for ``root_orientation``.
    root_position : ``(3,)`` pre-set root position, file length units.
    root_orientation : ``(3,)`` pre-set root orientation angles, file angle unit.
    units : ``{"mass": float, "length": float, "angle": "deg" | "rad"}`` (plus any
        other unit the file names, as a string).
    name : the ``:name`` of the skeleton, if any.
    path : the file it was read from, if any.
    """

    bones: tuple[str, ...]
    parents: tuple[str, ...]
    directions: np.ndarray
    lengths: np.ndarray
    axes: np.ndarray
    axis_orders: tuple[str, ...]
    dofs: tuple[tuple[str, ...], ...]
    limits: tuple[tuple[tuple[float, float], ...], ...] = ()
    root_order: tuple[str, ...] = _ROOT_ORDER_TOKENS
    root_axis: str = "XYZ"
    root_position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    root_orientation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    units: dict = field(default_factory=lambda: {"mass": 1.0, "length": 1.0, "angle": "deg"})
    name: str | None = None
    path: str | None = None

    def __post_init__(self):
        n = len(self.bones)
        for attr, shape in (("directions", (n, 3)), ("lengths", (n,)), ("axes", (n, 3)),
                            ("root_position", (3,)), ("root_orientation", (3,))):
            arr = np.array(getattr(self, attr), dtype=np.float64).reshape(shape)
            arr.setflags(write=False)
            object.__setattr__(self, attr, arr)
        if not self.limits:
            object.__setattr__(self, "limits", tuple(() for _ in range(n)))
        if not (len(self.parents) == len(self.axis_orders) == len(self.dofs)
                == len(self.limits) == n):
            raise MocycleError(f"AsfSkeleton fields disagree: {n} bones but "
                               f"{len(self.parents)} parents, {len(self.axis_orders)} axis "
                               f"orders, {len(self.dofs)} dof lists, {len(self.limits)} limits")

    # -- facts -----------------------------------------------------------
    @property
    def n_bones(self) -> int:
        return len(self.bones)

    @property
    def angle_unit(self) -> str:
        """``"deg"`` or ``"rad"``: the unit of ``axes``, ``root_orientation`` (and AMC
        values unless the AMC file says otherwise)."""
        return self.units.get("angle", "deg")

    def bone_index(self, name: str) -> int:
        """Index of bone ``name`` (exact, else case-insensitive match); ``-1`` for ``root``."""
        if name.lower() == ROOT:
            return -1
        if name in self.bones:
            return self.bones.index(name)
        lower = [b.lower() for b in self.bones]
        if lower.count(name.lower()) == 1:
            return lower.index(name.lower())
        raise MocycleError(f"no bone named {name!r}; bones are: {', '.join(self.bones)}")

    # -- rotations -------------------------------------------------------
    def axis_rotations(self) -> Rotation:
        """``C`` of every bone as one scipy ``Rotation`` of length ``N``."""
        if self.n_bones == 0:
            return Rotation.identity(0)
        degrees = self.angle_unit == "deg"
        return Rotation.concatenate([
            Rotation.from_euler(order.lower(), angles, degrees=degrees)
            for order, angles in zip(self.axis_orders, self.axes, strict=True)
        ])

    def root_axis_rotation(self) -> Rotation:
        """``C`` of the root, from ``orientation`` applied in ``root_axis`` order."""
        return Rotation.from_euler(self.root_axis.lower(), self.root_orientation,
                                   degrees=self.angle_unit == "deg")

    # -- the mocycle skeleton -------------------------------------------
    def to_skeleton(self) -> Skeleton:
        """The mocycle :class:`Skeleton`: ``root`` plus one joint per bone, at the bone's start.

        Offsets are in file length units: the root's is ``root_position``, a
        root child's is zero, any other joint's is its parent bone's
        ``direction * length``.  Each leaf bone gets an End Site at its end.
        """
        joint_of = {ROOT: 0}
        joint_of.update({b: i + 1 for i, b in enumerate(self.bones)})
        vectors = self.directions * self.lengths[:, None]
        parents = [-1] + [joint_of[p] for p in self.parents]
        offsets = np.zeros((self.n_bones + 1, 3))
        offsets[0] = self.root_position
        for i, p in enumerate(self.parents):
            if p != ROOT:
                offsets[i + 1] = vectors[joint_of[p] - 1]
        has_child = set(self.parents)
        end_sites = tuple(
            EndSite(parent=i + 1, offset=(float(vectors[i, 0]), float(vectors[i, 1]), float(vectors[i, 2])))
            for i, b in enumerate(self.bones) if b not in has_child
        )
        channels = (ROOT_CHANNELS,) + (BONE_CHANNELS,) * self.n_bones
        return Skeleton((ROOT,) + self.bones, np.asarray(parents), offsets, channels, end_sites)


# --------------------------------------------------------------------------
# public readers
# --------------------------------------------------------------------------
def read_asf(path: str | os.PathLike) -> AsfSkeleton:
    """Read an ``.asf`` skeleton file."""
    return _parse_asf(_read_text(path), path)


def parse_asf(text: str, path: str | os.PathLike | None = None) -> AsfSkeleton:
    """Parse ASF text (``path`` only names errors)."""
    return _parse_asf(text.replace("\r\n", "\n").replace("\r", "\n"), path)


def parse_amc(text: str, asf: AsfSkeleton, path: str | os.PathLike | None = None, fps: float = 120.0) -> Motion:
    """Parse AMC text for skeleton ``asf`` (``path`` only names errors)."""
    frame_time = _frame_time(fps)
    values, unit = _parse_amc(text.replace("\r\n", "\n").replace("\r", "\n"), path, asf)
    return _to_motion(asf, values, unit or asf.angle_unit, frame_time)


def read_amc(path: str | os.PathLike, asf: AsfSkeleton | str | os.PathLike,
             fps: float = AMC_FPS) -> Motion:
    """Read an ``.amc`` motion for skeleton ``asf`` (an :class:`AsfSkeleton` or its path).

    AMC files do not store the frame rate; ``fps`` gives it (CMU: 120).
    Returns a :class:`Motion` with ``T`` frames (one per AMC frame) and
    ``N + 1`` joints, lengths in the ASF's file units.
    """
    if not isinstance(asf, AsfSkeleton):
        asf = read_asf(asf)
    frame_time = _frame_time(fps)
    values, unit = _parse_amc(_read_text(path), path, asf)
    return _to_motion(asf, values, unit or asf.angle_unit, frame_time)


def read_asfamc(asf_path: str | os.PathLike, amc_path: str | os.PathLike,
                fps: float = AMC_FPS) -> Motion:
    """Read an ASF skeleton and an AMC motion into one :class:`Motion`."""
    return read_amc(amc_path, read_asf(asf_path), fps=fps)


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------
def _frame_time(fps) -> float:
    fps = _validate.positive("fps", fps)
    if frame_time_problem(1.0 / fps):
        raise MocycleError(f"fps must be a positive number within [1e-4, 1e6]; got {fps}")
    return 1.0 / fps


def _read_text(path) -> str:
    """The whole file as text, line ends (CRLF, CR, LF) turned into ``\\n``."""
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            return fh.read()
    except OSError as exc:
        raise MotionFileError(f"cannot read the file: {exc.strerror or exc}", path) from None


def _n_lines(text: str) -> int:
    return text.count("\n") + (0 if text.endswith("\n") else 1)


def _numbers(tokens, count, path, line, what, allow_inf=False) -> list[float]:
    """``count`` numbers from ``tokens``, or a MotionFileError saying what was expected."""
    if len(tokens) != count:
        raise MotionFileError(
            f"{what}: expected {count} number{'s' if count != 1 else ''}, got {len(tokens)} "
            f"({' '.join(tokens) or 'nothing'})", path, line)
    out = []
    for tok in tokens:
        try:
            v = float(tok)
        except ValueError:
            raise MotionFileError(f"{what}: expected a number, got {tok!r}", path, line) from None
        if math.isnan(v) or (math.isinf(v) and not allow_inf) or (math.isfinite(v) and abs(v) > MAX_MAGNITUDE):
            raise MotionFileError(f"{what}: expected a finite number within ±{MAX_MAGNITUDE:g}, got {tok!r}",
                                  path, line)
        out.append(v)
    return out


def _axis_order(token, path, line, what) -> str:
    order = token.upper()
    if len(order) != 3 or sorted(order) != ["X", "Y", "Z"]:
        raise MotionFileError(
            f"{what}: expected a rotation order such as XYZ (each of X, Y, Z once), got {token!r}",
            path, line)
    return order


# --------------------------------------------------------------------------
# ASF parsing
# --------------------------------------------------------------------------
class _Bone:
    """A bone block while it is being read."""

    def __init__(self, line: int):
        self.line = line
        self.name: str | None = None
        self.direction: list[float] | None = None
        self.length: float | None = None
        self.axis = [0.0, 0.0, 0.0]
        self.axis_order = "XYZ"
        self.dofs: tuple[str, ...] = ()
        self.limits: list[tuple[float, float]] = []
        self.last_key = ""


def _asf_lines(text: str):
    """``(line number, tokens)`` of each non-empty ASF line, comments removed."""
    for num, raw in enumerate(text.split("\n"), 1):
        tokens = raw.split("#", 1)[0].translate(_ASF_SEPARATORS).split()
        if tokens:
            yield num, tokens


def _bone_field(bone: _Bone, tokens: list[str], path, line: int) -> None:
    key = tokens[0].lower()
    args = tokens[1:]
    if key == "limits" or (bone.last_key == "limits" and _is_number(tokens[0])):
        pairs = args if key == "limits" else tokens
        if len(pairs) % 2:
            raise MotionFileError(f"limits: expected (min max) pairs, got {' '.join(pairs)}",
                                  path, line)
        vals = _numbers(pairs, len(pairs), path, line, "limits", allow_inf=True)
        bone.limits.extend(zip(vals[0::2], vals[1::2], strict=True))
        bone.last_key = "limits"
        return
    bone.last_key = key
    if key == "id":
        if len(args) != 1 or not args[0].lstrip("+-").isdigit():
            raise MotionFileError(f"id: expected one whole number, got {' '.join(args)!r}",
                                  path, line)
    elif key == "name":
        if len(args) != 1:
            raise MotionFileError(f"name: expected one bone name, got {' '.join(args)!r}",
                                  path, line)
        if args[0].lower() == ROOT:
            raise MotionFileError("a bone may not be called 'root' (that name is the root's)",
                                  path, line)
        bone.name = args[0]
    elif key == "direction":
        bone.direction = _numbers(args, 3, path, line, "direction")
    elif key == "length":
        bone.length = _numbers(args, 1, path, line, "length")[0]
    elif key == "axis":
        if len(args) == 4:
            bone.axis_order = _axis_order(args[3], path, line, "axis")
            args = args[:3]
        bone.axis = _numbers(args, 3, path, line, "axis (three angles and an order)")
    elif key == "dof":
        dofs = tuple(a.lower() for a in args)
        for d in dofs:
            if d in _TRANSLATION_DOFS:
                raise MotionFileError(
                    f"dof {d!r}: translation dofs on bones are not supported (only rx ry rz)",
                    path, line)
            if d not in _ROTATION_DOFS:
                raise MotionFileError(f"dof: expected rx, ry or rz, got {d!r}", path, line)
        if len(set(dofs)) != len(dofs):
            raise MotionFileError(f"dof: an axis is listed twice ({' '.join(args)})", path, line)
        bone.dofs = dofs
    elif key in ("bodymass", "cofmass"):
        pass
    else:
        raise MotionFileError(
            f"unknown bone keyword {tokens[0]!r}; expected id, name, direction, length, axis, "
            "dof, limits or end", path, line)


def _is_number(tok: str) -> bool:
    try:
        float(tok)
    except ValueError:
        return False
    return True


def _parse_asf(text: str, path) -> AsfSkeleton:
    """Parse ASF text; ``path`` is used in error messages."""
    last_line = _n_lines(text)
    units: dict = {"mass": 1.0, "length": 1.0, "angle": "deg"}
    name = None
    root: dict | None = None
    bones: dict[str, _Bone] = {}
    bonedata_line = None
    children: dict[str, list[str]] = {}
    parent_of: dict[str, str] = {}
    hierarchy_line = None
    hierarchy_state = ""  # "", "open", "closed"
    section = None
    block: _Bone | None = None

    for num, tokens in _asf_lines(text):
        key = tokens[0]
        low = key.lower()
        if key.startswith(":"):
            if block is not None:
                raise MotionFileError(
                    f"the bone block started at line {block.line} has no 'end' before {key}",
                    path, num)
            if hierarchy_state == "open":
                raise MotionFileError(
                    f"the :hierarchy started at line {hierarchy_line} has no 'end' before {key}",
                    path, num)
            section = low[1:]
            if section == "name":
                name = " ".join(tokens[1:]) or None
            elif section == "root":
                root = {"order": _ROOT_ORDER_TOKENS, "axis": "XYZ",
                        "position": [0.0] * 3, "orientation": [0.0] * 3}
            elif section == "bonedata":
                bonedata_line = num
            elif section == "hierarchy":
                if hierarchy_line is not None:
                    raise MotionFileError(
                        f"a second :hierarchy section (the first is at line {hierarchy_line})",
                        path, num)
                hierarchy_line = num
            continue
        if section is None:
            raise MotionFileError(
                f"expected an ASF keyword line such as ':version' or ':root', got {key!r}",
                path, num)
        if section == "units":
            if len(tokens) != 2:
                raise MotionFileError(
                    f"units: expected 'name value' (e.g. 'angle deg'), got {' '.join(tokens)!r}",
                    path, num)
            if low == "angle":
                unit = _ANGLE_UNITS.get(tokens[1].lower())
                if unit is None:
                    raise MotionFileError(f"units angle: expected deg or rad, got {tokens[1]!r}",
                                          path, num)
                units["angle"] = unit
            elif low in ("mass", "length"):
                units[low] = _numbers(tokens[1:], 1, path, num, f"units {low}")[0]
            else:
                units[low] = tokens[1]
        elif section == "root":
            assert root is not None  # made when the :root section starts
            args = tokens[1:]
            if low == "order":
                root_order = tuple(a.upper() for a in args)
                bad = [a for a in root_order if a not in _ROOT_ORDER_TOKENS]
                if bad or len(set(root_order)) != len(root_order):
                    raise MotionFileError(
                        "root order: expected each of TX TY TZ RX RY RZ at most once, "
                        f"got {' '.join(args)!r}", path, num)
                root["order"] = root_order
            elif low == "axis":
                if len(args) != 1:
                    raise MotionFileError("root axis: expected one order such as XYZ", path, num)
                root["axis"] = _axis_order(args[0], path, num, "root axis")
            elif low in ("position", "orientation"):
                root[low] = _numbers(args, 3, path, num, f"root {low}")
            else:
                raise MotionFileError(
                    f"unknown root keyword {key!r}; expected order, axis, position or orientation",
                    path, num)
        elif section == "bonedata":
            if low == "begin":
                if block is not None:
                    raise MotionFileError(
                        f"'begin' inside the bone block started at line {block.line}; "
                        "expected 'end' first", path, num)
                block = _Bone(num)
            elif low == "end":
                if block is None:
                    raise MotionFileError("'end' without a matching 'begin'", path, num)
                _finish_bone(block, bones, path)
                block = None
            elif block is None:
                raise MotionFileError(f"expected 'begin' of a bone block, got {key!r}", path, num)
            else:
                _bone_field(block, tokens, path, num)
        elif section == "hierarchy":
            if low == "begin" and hierarchy_state == "":
                hierarchy_state = "open"
            elif low == "end" and hierarchy_state == "open":
                hierarchy_state = "closed"
            elif hierarchy_state != "open":
                raise MotionFileError(
                    f"expected 'begin' or 'end' of the :hierarchy, got {key!r}", path, num)
            else:
                _hierarchy_line(tokens, bones, children, parent_of, path, num)
        # other sections (:version, :documentation, :skin, ...) are skipped

    if block is not None:
        raise MotionFileError(
            f"the file ends inside the bone block started at line {block.line} "
            "(expected 'end'); is it truncated?", path, last_line)
    if root is None:
        raise MotionFileError("no :root section (expected ':root' with order, axis, "
                              "position, orientation); is this an ASF file?", path, last_line)
    if bonedata_line is None:
        raise MotionFileError("no :bonedata section (expected the bone definitions); "
                              "is this an ASF file?", path, last_line)
    if hierarchy_state != "closed":
        what = "no :hierarchy section" if hierarchy_line is None else (
            f"the :hierarchy started at line {hierarchy_line} has no "
            + ("'begin'" if hierarchy_state == "" else "'end'"))
        raise MotionFileError(f"{what}; is the file truncated?", path, last_line)

    order = _depth_first(children)
    missing = [b for b in bones if b not in parent_of]
    if missing:
        raise MotionFileError(
            f"bones missing from the :hierarchy: {', '.join(missing)}", path, hierarchy_line)
    unreachable = [b for b in bones if b not in order]
    if unreachable:
        raise MotionFileError(
            f"bones not connected to the root in the :hierarchy (a loop?): "
            f"{', '.join(unreachable)}", path, hierarchy_line)

    chosen = [bones[b] for b in order]
    return AsfSkeleton(
        bones=tuple(order),
        parents=tuple(parent_of[b] for b in order),
        directions=np.array([b.direction for b in chosen]).reshape(-1, 3),
        lengths=np.array([b.length for b in chosen]),
        axes=np.array([b.axis for b in chosen]).reshape(-1, 3),
        axis_orders=tuple(b.axis_order for b in chosen),
        dofs=tuple(b.dofs for b in chosen),
        limits=tuple(tuple(b.limits) for b in chosen),
        root_order=tuple(root["order"]),
        root_axis=root["axis"],
        root_position=root["position"],
        root_orientation=root["orientation"],
        units=units,
        name=name,
        path=str(path),
    )


def _finish_bone(bone: _Bone, bones: dict[str, _Bone], path) -> None:
    for attr in ("name", "direction", "length"):
        if getattr(bone, attr) is None:
            raise MotionFileError(f"the bone block has no {attr!r} line", path, bone.line)
    assert bone.name is not None  # checked just above
    if bone.name in bones:
        raise MotionFileError(
            f"bone {bone.name!r} is defined twice (first at line {bones[bone.name].line})",
            path, bone.line)
    bones[bone.name] = bone


def _hierarchy_line(tokens, bones, children, parent_of, path, num) -> None:
    parent, kids = tokens[0], tokens[1:]
    if parent != ROOT and parent not in bones:
        raise MotionFileError(
            f"hierarchy: unknown bone {parent!r}; expected 'root' or a bone from :bonedata",
            path, num)
    for kid in kids:
        if kid not in bones:
            raise MotionFileError(
                f"hierarchy: unknown bone {kid!r} (child of {parent!r}); "
                "expected a bone from :bonedata", path, num)
        if kid in parent_of:
            raise MotionFileError(
                f"hierarchy: bone {kid!r} already has the parent {parent_of[kid]!r}", path, num)
        parent_of[kid] = parent
        children.setdefault(parent, []).append(kid)


def _depth_first(children: dict[str, list[str]]) -> list[str]:
    """Bone names below ``root`` in depth-first order, children in listed order."""
    order: list[str] = []
    stack = list(reversed(children.get(ROOT, [])))
    while stack:
        bone = stack.pop()
        order.append(bone)
        stack.extend(reversed(children.get(bone, [])))
    return order


# --------------------------------------------------------------------------
# AMC parsing
# --------------------------------------------------------------------------
def _parse_amc(text: str, path, asf: AsfSkeleton) -> tuple[list[np.ndarray], str | None]:
    """Dof values per joint, ``[(T, len(root_order)), (T, len(dofs[i])) ...]``, and the
    angle unit the AMC header names (``None`` if it names none)."""
    names = (ROOT,) + asf.bones
    expected = (len(asf.root_order),) + tuple(len(d) for d in asf.dofs)
    labels = (asf.root_order,) + asf.dofs
    lookup = {n: j for j, n in enumerate(names)}
    lower = [n.lower() for n in names]
    counts = Counter(lower)
    lookup_lower = {n: j for j, n in enumerate(lower) if counts[n] == 1}
    J = len(names)
    rows: list[list[list[str]]] = [[] for _ in range(J)]
    frames: list[list[int]] = [[] for _ in range(J)]
    lines: list[list[int]] = [[] for _ in range(J)]
    seen = [-1] * J
    per_frame: list[int] = []
    frame = -1
    number = None
    unit = None

    for num, raw in enumerate(text.split("\n"), 1):
        tokens = raw.split()
        if not tokens:
            continue
        head = tokens[0]
        if head[0] == "#":
            continue
        if head[0] == ":":
            upper = head.upper()
            if upper == ":DEGREES":
                unit = "deg"
            elif upper == ":RADIANS":
                unit = "rad"
            continue
        if len(tokens) == 1 and head.isdecimal():
            n = int(head)
            if number is not None and n != number + 1:
                raise MotionFileError(
                    f"frame number {n} follows frame {number}; expected {number + 1} "
                    "(frame numbers must increase by one)", path, num)
            number = n
            frame += 1
            per_frame.append(0)
            continue
        j = lookup.get(head)
        if j is None:
            j = lookup_lower.get(head.lower())
        if j is None:
            raise MotionFileError(
                f"unknown bone {head!r}; expected a frame number or a bone of the ASF skeleton "
                f"({asf.path or 'given'})", path, num)
        if frame < 0:
            raise MotionFileError(
                f"bone {head!r} before the first frame number; expected a frame number line",
                path, num)
        if len(tokens) - 1 != expected[j]:
            raise MotionFileError(
                f"bone {names[j]!r} has {len(tokens) - 1} values; expected {expected[j]} "
                f"({' '.join(labels[j]) or 'none'})", path, num)
        if seen[j] == frame:
            raise MotionFileError(
                f"bone {names[j]!r} appears twice in frame {number}", path, num)
        seen[j] = frame
        per_frame[-1] += 1
        rows[j].append(tokens[1:])
        frames[j].append(frame)
        lines[j].append(num)

    if frame < 0:
        raise MotionFileError("no frames found; expected a frame number line followed by "
                              "'bone value ...' lines", path, _n_lines(text))
    T = frame + 1
    if T > 1 and per_frame[-1] < per_frame[0]:
        warnings.warn(
            f"{path}: the last frame ({number}) has {per_frame[-1]} bone lines but the first "
            f"has {per_frame[0]}; the file may be truncated (missing bones are set to zero)",
            MocycleWarning, stacklevel=3)

    values = []
    for j in range(J):
        data = np.zeros((T, expected[j]))
        if rows[j] and expected[j]:
            try:
                arr = np.array(rows[j], dtype=np.float64)
            except ValueError:
                arr = None
            bad = (np.flatnonzero(~np.all(np.isfinite(arr) & (np.abs(arr) <= MAX_MAGNITUDE), axis=1))
                   if arr is not None
                   else [_first_bad_row(rows[j])])
            if len(bad):
                k = int(bad[0])
                raise MotionFileError(
                    f"bone {names[j]!r}: expected {expected[j]} finite numbers within ±{MAX_MAGNITUDE:g} "
                    f"({' '.join(labels[j])}), got {' '.join(rows[j][k])!r}", path, lines[j][k])
            data[frames[j]] = arr
        values.append(data)
    return values, unit


def _first_bad_row(rows: list[list[str]]) -> int:
    for k, row in enumerate(rows):
        for tok in row:
            try:
                if not math.isfinite(float(tok)):
                    return k
            except ValueError:
                return k
    return 0


def _to_motion(asf: AsfSkeleton, values: list[np.ndarray], unit: str,
               frame_time: float) -> Motion:
    """Local rotations ``C · M · C⁻¹`` for all frames at once, one scipy call per joint."""
    T = values[0].shape[0]
    degrees = unit == "deg"
    quats = np.empty((T, asf.n_bones + 1, 4))

    root = values[0]
    root_pos = np.broadcast_to(asf.root_position, (T, 3)).copy()
    rot_cols, rot_axes = [], ""
    for c, tok in enumerate(asf.root_order):
        if tok[0] == "T":
            root_pos[:, "XYZ".index(tok[1])] += root[:, c]
        else:
            rot_cols.append(c)
            rot_axes += tok[1].lower()
    quats[:, 0] = _conjugated(asf.root_axis_rotation(), rot_axes, root[:, rot_cols], degrees)

    axis_rots = asf.axis_rotations()
    for i, dofs in enumerate(asf.dofs):
        axes = "".join(d[1] for d in dofs)
        quats[:, i + 1] = _conjugated(axis_rots[i], axes, values[i + 1], degrees)

    try:
        return Motion(asf.to_skeleton(), quats, None, frame_time, root_positions=root_pos)
    except MocycleError as exc:
        raise MotionFileError(f"cannot build a motion from this file: {exc}",
                              asf.path) from None


def _conjugated(C: Rotation, axes: str, angles: np.ndarray, degrees: bool) -> np.ndarray:
    """``(T, 4)`` quaternions of ``C · M · C⁻¹``, ``M`` = extrinsic rotations about ``axes``."""
    T = angles.shape[0]
    if not axes:
        q = np.zeros((T, 4))
        q[:, 3] = 1.0
        return q
    m = Rotation.from_euler(axes, angles, degrees=degrees).as_quat()
    c = C.as_quat()
    c_inv = c * np.array([-1.0, -1.0, -1.0, 1.0])
    return _qmul(_qmul(c, m), c_inv)


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of ``(..., 4)`` scalar-last quaternions (broadcasting)."""
    av, aw = a[..., :3], a[..., 3:]
    bv, bw = b[..., :3], b[..., 3:]
    vec = aw * bv + bw * av + np.cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([vec, w], axis=-1)
