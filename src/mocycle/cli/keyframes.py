"""``mocycle compress``, ``mocycle decompress``, ``mocycle project``: keyframe compression (thesis 002)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ..errors import MocycleError
from ..io import read_motion as read
from ..io import write
from .common import (
    FORCE_HELP,
    app,
    check_output,
    friendly,
    json_text,
    out,
)

_SELECT_HELP = "Keyframe selection: uniform, scs (curve simplification), pb (position based) or rols."
_PROJECTION_HELP = "2-D projection of the spatial scheme: pca, mds, isomap, lle, force, tsne, rbfp or lamp."
_SEED_HELP = "First-step projection of rbfp and lamp (the keyframes' 2-D places): pca, mds, isomap, lle, force, tsne."


def _ratio(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise MocycleError(f"--ratio must be 'auto' or a number in (0, 1]; got {text!r}") from None


@app.command()
@friendly
def compress(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The .mck file to write.")],
    ratio: Annotated[str, typer.Option(
        help="Keyframes as a fraction of the frames (thesis: 0.03), or 'auto': 4 per period of the take's own "
             "rhythm, at least 3% and 6 keys.")] = "auto",
    select: Annotated[str, typer.Option(help=_SELECT_HELP)] = "uniform",
    scheme: Annotated[str, typer.Option(
        help="Reconstruction: linear, hermite (Euler angles), slerp (quaternions), rbf (1-D RBF in time) or "
             "spatial (2-D projection + Igarashi back-projection).")] = "slerp",
    projection: Annotated[str, typer.Option(help=_PROJECTION_HELP)] = "mds",
    seed: Annotated[str, typer.Option(help=_SEED_HELP)] = "mds",
    optimize: Annotated[bool, typer.Option("--optimize", help="Optimise the 2-D trajectory (Algorithm 12).")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Compress a take to keyframes (and a 2-D trajectory for the spatial scheme); report error and size.

    The default ratio 'auto' keeps enough keys for the motion's own rhythm; an explicit ratio that leaves
    fewer than 4 keys per period gets a warning.
    """
    from ..keyframes import compress as compress_motion
    from ..keyframes import error_per_frame_per_joint, keyframe_density

    check_output(output, [path], force, ".mck")
    r = ratio if ratio == "auto" else _ratio(ratio)
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    density = keyframe_density(motion, r, scheme)
    packed = compress_motion(motion, count=density.count, select=select, scheme=scheme, projection=projection,
                             optimize=optimize, seed=seed)
    rebuilt = packed.decompress()
    packed.save(output)
    bvh_bytes = path.stat().st_size if path.suffix.lower() == ".bvh" else None
    size = packed.size_report(bvh_bytes)
    facts = {"frames": motion.n_frames, "keyframes": packed.n_keyframes, "ratio": r,
             "period_frames": density.period_frames, "keys_per_period": density.keys_per_period,
             "keyframes_set_by": density.rule,
             "error_per_frame_per_joint": error_per_frame_per_joint(motion, rebuilt),
             "compressed_bytes": size["compressed_bytes"], "bvh_bytes": size["bvh_bytes"],
             "seconds": time.perf_counter() - t0}
    if as_json:
        print(json_text(facts))
        return
    what = scheme if scheme != "spatial" else f"spatial/{projection}" + ("/optimised" if optimize else "")
    table = Table(title=f"{path.name} -> {output.name} ({what}, {select} keyframes)")
    table.add_column("")
    table.add_column("value", justify="right")
    table.add_row("frames", str(facts["frames"]))
    table.add_row("keyframes", f"{facts['keyframes']} ({size['keyframe_ratio']:.1%}, set by {density.rule})")
    if density.period_frames is not None:
        table.add_row("keys per period", f"{density.keys_per_period:.1f} (period {density.period_frames:.1f} frames)")
    table.add_row("error per frame per joint (eq. 3.2, rad)", f"{facts['error_per_frame_per_joint']:.4f}")
    table.add_row("compressed bytes", f"{facts['compressed_bytes']:,}")
    table.add_row("BVH bytes", f"{facts['bvh_bytes']:,}")
    table.add_row("real ratio", f"{size['real_ratio']:.2%}")
    table.add_row("formula 5.2/5.3 ratio (h = 0)", f"{size['formula_ratio']:.2%}")
    table.add_row("seconds", f"{facts['seconds']:.2f}")
    out.print(table)


@app.command()
@friendly
def decompress(
    path: Annotated[Path, typer.Argument(help="A .mck file written by 'mocycle compress'.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The .bvh file to write.")],
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Rebuild a take from its keyframes; the keyframes come back exactly."""
    from ..keyframes import read_compressed

    check_output(output, [path], force, ".bvh")
    packed = read_compressed(path)
    motion = packed.decompress()
    write(motion, output)
    out.print(f"{output}: {motion.n_frames} frames rebuilt from {packed.n_keyframes} keyframes ({packed.scheme})")


@app.command()
@friendly
def project(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    projection: Annotated[str, typer.Option(help=_PROJECTION_HELP)] = "mds",
    select: Annotated[str, typer.Option(help=_SELECT_HELP)] = "uniform",
    ratio: Annotated[float, typer.Option(help="Keyframes as a fraction of the frames.")] = 0.03,
    seed: Annotated[str, typer.Option(help=_SEED_HELP)] = "mds",
    optimize: Annotated[bool, typer.Option("--optimize", help="Also optimise the projection (Algorithm 12) "
                                                               "and plot both.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: poses as points coloured by time, keyframes "
                                                   "marked (thesis Figure 6.2).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON (includes the 2-D points).")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Project every pose to 2-D and pick keyframes: the spatial keyframing view of a take."""
    from ..keyframes import PoseSpace, keyframe_count, optimize_projection, spatial_layout, stress

    check_output(plot, [path], force, ".png", "--plot")
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    space = PoseSpace(motion)
    k = keyframe_count(motion.n_frames, ratio=ratio)
    key, points = spatial_layout(space, projection, select, k, seed=seed)
    opt = optimize_projection(points, key, motion.rotations, space.weights).points if optimize else None
    facts = {"frames": motion.n_frames, "keyframes": key.tolist(), "projection": projection, "select": select,
             "stress": stress(space.distances, points) if motion.n_frames > 1 else None}
    if opt is not None:
        facts["stress_optimized"] = stress(space.distances, opt)
    if plot is not None:
        from ..viz.keyframes import plot_projection

        name = projection if projection not in ("rbfp", "lamp") else f"{projection} ({seed} seed)"
        plot_projection(points, key, plot, title=f"{path.name}: {name}, {select} keyframes", optimized=opt,
                        labels=(name, f"{name}, optimised (Algorithm 12)"))
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        facts["points"] = points.round(6).tolist()
        if opt is not None:
            facts["points_optimized"] = opt.round(6).tolist()
        print(json_text(facts, indent=None))
        return
    out.print(f"[bold]{path}[/]: {facts['frames']} frames, {len(key)} keyframes ({select}), projection {projection}")
    out.print(f"  stress (eq. 4.1): {facts['stress']:.4g}" + (
        f", optimised {facts['stress_optimized']:.4g}" if opt is not None else ""))
    out.print(f"  keyframes: {', '.join(map(str, key.tolist()))}", soft_wrap=True)
    out.print(f"  {facts['seconds']:.2f} s")
