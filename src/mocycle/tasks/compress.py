"""``compress``: a take as keyframes (and a 2-D trajectory for the spatial scheme), thesis 002."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..defaults import KEY_SCHEMES as SCHEME_CHOICES
from . import fields, keyframe_fields
from .options import Choice, Real, option
from .options import Options as _Options
from .report import Recorder, Report, is_motion, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``compress``."""

    ratio: float | str = option("auto", "Keyframes as a fraction of the frames (thesis: 0.03), or 'auto': 4 per "
                                        "period of the take's own rhythm, at least 3% and 6 keys.",
                                Real(0, 1, low_open=True, words=("auto",)))
    select: str = keyframe_fields.select()
    scheme: str = option("slerp", "Reconstruction: linear, hermite (Euler angles), slerp (quaternions), rbf (1-D RBF "
                                  "in time) or spatial (2-D projection + Igarashi back-projection).",
                         Choice(SCHEME_CHOICES))
    projection: str = keyframe_fields.projection()
    seed_projection: str = keyframe_fields.seed_projection()
    optimize: bool = keyframe_fields.optimize()
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def run(take, options: Options | None = None) -> Report:
    """Compress a take: ``result`` is the :class:`~mocycle.keyframes.Compressed` (``.save(path)`` writes the
    ``.mck``), ``motions["decompressed"]`` what it decodes to."""
    from ..keyframes import compress, error_per_frame_per_joint, keyframe_density

    o = options or Options()
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        density = keyframe_density(motion, o.ratio, o.scheme)
        packed = compress(motion, count=density.count, select=o.select, scheme=o.scheme, projection=o.projection,
                          optimize=o.optimize, seed=o.seed_projection)
        rebuilt = packed.decompress()
        is_bvh = not is_motion(take) and Path(take).suffix.lower() == ".bvh"
        size = packed.size_report(Path(take).stat().st_size if is_bvh else None)
        facts = {"frames": motion.n_frames, "keyframes": packed.n_keyframes, "ratio": o.ratio,
                 "period_frames": density.period_frames, "keys_per_period": density.keys_per_period,
                 "keyframes_set_by": density.rule,
                 "error_per_frame_per_joint": error_per_frame_per_joint(motion, rebuilt),
                 "compressed_bytes": size["compressed_bytes"], "bvh_bytes": size["bvh_bytes"],
                 "keyframe_ratio": size["keyframe_ratio"], "real_ratio": size["real_ratio"],
                 "formula_ratio": size["formula_ratio"]}
    return rec.report("compress", facts, {"decompressed": rebuilt}, packed)
