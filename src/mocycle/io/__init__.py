"""Reading and writing every file mocycle reads or writes.  Nothing else lives here.

One way in and one way out, chosen by the file's suffix:

=========  ==========================================  =======================================
suffix     holds                                       :func:`read` returns / :func:`write` takes
=========  ==========================================  =======================================
``.bvh``   a motion (:mod:`.bvh`)                      :class:`~mocycle.motion.Motion`
``.glb``   a motion as binary glTF (:mod:`.gltf`,       :class:`~mocycle.motion.Motion`
           read by :mod:`.gltf_read`)
``.gltf``  a motion as glTF text (:mod:`.gltf_read`)   :class:`~mocycle.motion.Motion` (read only)
``.fbx``   a motion in an FBX file (:mod:`.fbx`)       :class:`~mocycle.motion.Motion` (read only)
``.amc``   a CMU motion, skeleton in an ``.asf``       :class:`~mocycle.motion.Motion` (read only)
``.mck``   a keyframe-compressed take (:mod:`.mck`)    :class:`~mocycle.keyframes.Compressed`
                                                       (read by :func:`mocycle.read`)
``.mosw``  joint swings, compact (:mod:`.mosw`)        :class:`~mocycle.swings.Segmentation`
``.json``  joint swings as JSON records                :class:`~mocycle.swings.Segmentation`
=========  ==========================================  =======================================

``write`` also writes any result that has a ``to_dict()`` (cycles, phases, reports) as
``.json``.  io imports no algorithm: a ``.mck`` file is decoded here (:func:`.mck.decode`) and made into the
take it holds by :func:`mocycle.read` (:mod:`mocycle.files`), which sits above io and the keyframe package.
:func:`read_motion` is :func:`read` for the files that hold a motion (``.bvh``, ``.amc``, ``.glb``, ``.gltf``,
``.fbx``), which is what the commands that take a motion use.
glTF and FBX files may hold several animations (takes): ``take`` names one (:func:`takes` lists them).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from ..errors import MotionFileError
from ..motion import Motion
from ..suffixes import MOTION_READ_SUFFIXES, MOTION_WRITE_SUFFIXES, MULTI_TAKE_SUFFIXES, READ_SUFFIXES, WRITE_SUFFIXES
from ..text import indented_json
from .asfamc import AMC_FPS, read_amc, read_asf, read_asfamc
from .atomic import atomic_write
from .bvh import parse_bvh, read_bvh, write_bvh

__all__ = ["AMC_FPS", "MOTION_READ_SUFFIXES", "MOTION_WRITE_SUFFIXES", "MULTI_TAKE_SUFFIXES", "READ_SUFFIXES",
           "WRITE_SUFFIXES", "parse_bvh", "read", "read_amc", "read_asf", "read_asfamc", "read_bvh", "read_motion",
           "takes", "write", "write_bvh"]


def _suffix(p: Path, known: tuple[str, ...], what: str) -> str:
    """The lower-case suffix of ``p`` if it is one of ``known``; otherwise one clear error."""
    if p.is_dir():
        raise MotionFileError(f"is a folder; {what} a file ending in {', '.join(known)}", p)
    suffix = p.suffix.lower()
    if suffix not in known:
        raise MotionFileError(f"unknown file type {suffix or '(no suffix)'!r}; {what} {', '.join(known)} files",
                              p)
    return suffix


def takes(path: str | os.PathLike) -> list[str]:
    """The names of the takes (glTF animations, FBX animation stacks) a motion file holds; one for other files
    (its stem)."""
    p = Path(path)
    suffix = _suffix(p, MOTION_READ_SUFFIXES, "mocycle reads motions from")
    if suffix in (".glb", ".gltf"):
        from .gltf_read import gltf_takes

        return gltf_takes(p)
    if suffix == ".fbx":
        from .fbx import fbx_takes

        return fbx_takes(p)
    return [p.stem]


def read_motion(path: str | os.PathLike, *, asf: str | os.PathLike | None = None, fps: float = AMC_FPS,
                take: str | None = None, sample_fps: float | None = None) -> Motion:
    """Read a motion file (``.bvh``, ``.glb``, ``.gltf``, ``.fbx``, or ``.amc`` with its ``.asf``) into a
    :class:`Motion`.

    Parameters
    ----------
    path : the motion file.
    asf : the ``.asf`` skeleton of an ``.amc`` file; default: the one beside it (same
        subject number, or the only one).
    fps : frame rate of ``.amc`` files, which do not store it (CMU: 120).
    take : glTF and FBX only: the animation (stack) to read, by name or 0-based index; default the first that
        moves the skeleton (a :class:`~mocycle.errors.DefaultTake` warning says which).
        Other files hold one take: a name other than their stem is an error.
    sample_fps : glTF and FBX only: the frame rate to sample the animation at; default the file's own (glTF: the
        keys' rate when regular, else 30; FBX: the scene's frame rate).

    Raises
    ------
    MotionFileError
        The file is missing, a folder, of another type, or not what its suffix promises
        (the message names the file and the line).
    """
    p = Path(path)
    suffix = _suffix(p, MOTION_READ_SUFFIXES, "mocycle reads motions from")
    if suffix in (".glb", ".gltf"):
        from .gltf_read import read_gltf

        return read_gltf(p, take=take, fps=sample_fps)
    if suffix == ".fbx":
        from .fbx import read_fbx

        return read_fbx(p, take=take, fps=sample_fps)
    if take is not None and str(take) not in (p.stem, "0"):
        raise MotionFileError(f"no take named {take!r}: a {suffix} file holds one take", p)
    if suffix == ".bvh":
        return read_bvh(p)
    if asf is None:
        candidates = sorted(p.parent.glob("*.asf")) + sorted(p.parent.glob("*.ASF"))
        stem = p.stem.split("_")[0]
        named = [c for c in candidates if c.stem == stem]
        if len(named) == 1:
            asf = named[0]
        elif len(candidates) == 1:
            asf = candidates[0]
        else:
            raise MotionFileError("cannot tell which .asf skeleton goes with this .amc; pass it explicitly", p)
    return read_asfamc(asf, p, fps=fps)


def read(path: str | os.PathLike, *, asf: str | os.PathLike | None = None, fps: float = AMC_FPS,
         take: str | None = None, sample_fps: float | None = None):
    """Read any file mocycle writes, chosen by its suffix (table in the module notes).

    Parameters
    ----------
    path : a ``.bvh``, ``.amc``, ``.glb``, ``.gltf``, ``.fbx``, ``.mosw`` or swings ``.json`` file (a ``.mck``
        file: :func:`mocycle.read`).
    asf, fps : for ``.amc`` files only (see :func:`read_motion`).
    take, sample_fps : for ``.glb``, ``.gltf`` and ``.fbx`` files (see :func:`read_motion`).

    Returns
    -------
    Motion or Segmentation
        A :class:`Motion` for ``.bvh``/``.amc``/``.glb``/``.gltf``/``.fbx``, a
        :class:`~mocycle.swings.Segmentation` for ``.mosw`` and swings ``.json`` (``mocycle.swings.playback``
        gives the motion).

    Raises
    ------
    MotionFileError
        Unknown suffix or a folder (the message lists the known suffixes), a ``.mck`` file (read by
        :func:`mocycle.read`), or a damaged file.

    Examples
    --------
    >>> import mocycle, tempfile, pathlib
    >>> from mocycle.datasets import synthetic_walk
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> walk = synthetic_walk(n_frames=120, fps=60).motion
    >>> path = mocycle.write(walk, folder / "walk.bvh")
    >>> again = mocycle.read(path)
    >>> again.n_frames, round(again.fps)
    (120, 60)
    >>> mocycle.read(folder / "walk.txt")
    Traceback (most recent call last):
    ...
    mocycle.errors.MotionFileError: ...walk.txt: unknown file type '.txt'; mocycle reads .bvh, .amc, ... files
    """
    p = Path(path)
    suffix = _suffix(p, READ_SUFFIXES, "mocycle reads")
    if suffix in MOTION_READ_SUFFIXES:
        return read_motion(p, asf=asf, fps=fps, take=take, sample_fps=sample_fps)
    if suffix == ".mck":
        raise MotionFileError("holds a keyframe-compressed take, which io does not build: read it with "
                              "mocycle.read or mocycle.keyframes.read_compressed", p)
    if suffix == ".mosw":
        from .mosw import read_swings

        return read_swings(p)
    return _read_json(p)


def _read_json(p: Path):
    """The swings records ``mocycle swings -o FILE.json`` writes, as a Segmentation (every field checked)."""
    from .swings_json import read_swings_json

    return read_swings_json(p)


def write(obj, path: str | os.PathLike, *, clip=None, gltf_scale: float | str = "auto", gltf_up=None) -> Path:
    """Write ``obj`` to ``path`` in the format its suffix names, atomically (no half-written file).

    Parameters
    ----------
    obj : a :class:`Motion` (``.bvh`` or ``.glb``), a :class:`~mocycle.keyframes.Compressed` take (``.mck``), a
        :class:`~mocycle.swings.Segmentation` (``.mosw`` or ``.json``), or any result with a
        ``to_dict()`` (``.json``).
    path : the file to write.
    clip : ``.glb`` only (other formats have no place for it): the animation clip's name and loop facts, a
        :class:`~mocycle.clip.Clip` or a name (default: the file's stem).
    gltf_scale, gltf_up : ``.glb`` only: metres per motion unit (or ``"auto"``, or a unit name) and the
        motion's vertical (``None``: detected); see :func:`mocycle.io.gltf.gltf_frame`.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    MotionFileError
        The suffix is unknown, names a folder, or does not fit ``obj`` (the message says which suffixes do).

    Examples
    --------
    >>> import mocycle, tempfile, pathlib
    >>> from mocycle.datasets import synthetic_walk
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> mocycle.write(synthetic_walk(n_frames=60).motion, folder / "walk.bvh").name
    'walk.bvh'
    >>> mocycle.write(synthetic_walk(n_frames=60).motion, folder / "walk.mosw")
    Traceback (most recent call last):
    ...
    mocycle.errors.MotionFileError: .../walk.mosw: a Motion is written as .bvh or .glb
    """
    p = Path(path)
    suffix = _suffix(p, WRITE_SUFFIXES, "mocycle writes")
    # the kinds whose modules are loaded (an object of a kind whose module is not loaded cannot exist; so writing
    # a motion does not import the keyframe and swing packages)
    kinds = {"mocycle.motion.Motion": MOTION_WRITE_SUFFIXES, "mocycle.keyframes.compressed.Compressed": (".mck",),
             "mocycle.segmentation.Segmentation": (".mosw", ".json")}
    fits = {getattr(sys.modules.get(name.rsplit(".", 1)[0]), name.rsplit(".", 1)[1], None): suffixes
            for name, suffixes in kinds.items()}
    for kind, suffixes in fits.items():
        if kind is not None and isinstance(obj, kind):
            if suffix not in suffixes:
                raise MotionFileError(f"a {kind.__name__} is written as {' or '.join(suffixes)}", p)
            break
    else:
        if suffix != ".json" or not callable(getattr(obj, "to_dict", None)):
            raise MotionFileError(f"cannot write a {type(obj).__name__} as {suffix}: mocycle writes a Motion as "
                                  f".bvh or .glb, a Compressed take as .mck, swings as .mosw or .json, results with "
                                  f"to_dict() as .json", p)
    if suffix == ".bvh":
        return write_bvh(obj, p)
    if suffix == ".glb":
        from ..clip import Clip
        from .gltf import write_gltf

        if isinstance(clip, str):
            clip = Clip(name=clip)
        return write_gltf(obj, p, clip=clip, scale=gltf_scale, up=gltf_up)
    if suffix == ".mck":
        return obj.save(p)
    if suffix == ".mosw":
        from .mosw import write_swings

        return write_swings(obj, p)
    if suffix == ".json" and fits.get(type(obj)) == (".mosw", ".json"):  # a Segmentation: the swings document
        from .swings_json import swings_document

        document = swings_document(obj)
    else:
        document = obj.to_dict()
    try:
        return atomic_write(p, indented_json(document, indent=1))  # json.dumps' text, at C speed
    except OSError as exc:
        raise MotionFileError(f"cannot write file ({exc.strerror or exc})", p) from None
