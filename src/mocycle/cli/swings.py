"""``mocycle swings``, ``mocycle search``, ``mocycle edit``: joint swings (paper 003)."""

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
    write_text,
)

_JOINTS_HELP = "Joints to segment: names, glob patterns or groups (legs, arms, spine), comma-separated " \
               "(default: the major bones, by name and motion energy)."
_THRESHOLD_HELP = "Acceptable Swing Error, 0-2 (paper: 0.4; 0 accepts only perfectly geodesic swings)."


def _load(path: Path, threshold: float, joints: str | None, fps: float):
    """(motion or None, segmentation) from a motion file or a .mosw swings file."""
    from ..swings import read_swings, segment

    if path.suffix.lower() == ".mosw":
        return None, read_swings(path)
    motion = read(path, fps=fps)
    return motion, segment(motion, threshold=threshold, joints=joints)


@app.command()
@friendly
def swings(
    path: Annotated[Path, typer.Argument(help="A .bvh or .amc file, or a .mosw swings file to play back.")],
    threshold: Annotated[float, typer.Option(help=_THRESHOLD_HELP)] = 0.4,
    joints: Annotated[str | None, typer.Option(help=_JOINTS_HELP)] = None,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="Write the swings: .json (records) or .mosw (compact binary file).")] = None,
    playback_path: Annotated[Path | None, typer.Option(
        "--playback", help="Write the motion rebuilt from the swings as BVH.")] = None,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: one row per joint, swings as bars in time.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Segment a take into joint swings and holds; report playback error and compressed size."""
    from ..swings import encode, playback, playback_errors, size_report

    check_output(output, [path], force, (".json", ".mosw"))
    check_output(playback_path, [path], force, ".bvh", "--playback")
    check_output(plot, [path], force, ".png", "--plot")
    t0 = time.perf_counter()
    motion, seg = _load(path, threshold, joints, fps)
    seconds = time.perf_counter() - t0
    rebuilt = playback(seg)
    facts = {"joints": [seg.skeleton.names[j] for j in seg.joints], "n_swings": seg.n_swings}
    if motion is not None:
        errs = playback_errors(motion, rebuilt)
        facts.update({k: errs[k] for k in ("segmentation_error", "per_angle_error_deg", "geodesic_error_deg")})
        size = size_report(seg, motion)
    else:
        facts.update(segmentation_error=None, per_angle_error_deg=None, geodesic_error_deg=None)
        size = size_report(seg)
    facts.update(compressed_bytes=size["compressed_bytes"], raw_float32_bytes=size["raw_float32_bytes"],
                 seconds=seconds)
    if output is not None:
        if output.suffix.lower() == ".json":
            write_text(output, json_text(seg.to_dict(), indent=1), "swings")
        else:
            write_text(output, encode(seg), "swings file")
    if playback_path is not None:
        write(rebuilt, playback_path)
    if plot is not None:
        from ..viz.swings import plot_swings

        plot_swings(seg, plot, title=f"{path.name}: {seg.n_swings} swings (threshold {seg.threshold:g})")
    if as_json:
        print(json_text(facts))
        return
    out.print(f"[bold]{path}[/]: {seg.n_frames} frames at {seg.fps:.6g} fps, "
              f"Acceptable Swing Error {seg.threshold:g}")
    table = Table(title="swings per joint")
    for col in ("joint", "swings", "mean length s", "mean angle deg", "holds"):
        table.add_column(col, justify="left" if col == "joint" else "right")
    for j in seg.joints:
        sw = seg.swings_of(j)
        mlen = sum(s.end - s.start for s in sw) / len(sw) * seg.frame_time if sw else 0.0
        mang = sum(abs(s.end_angle - s.start_angle) for s in sw) / len(sw) * 57.29577951308232 if sw else 0.0
        table.add_row(seg.skeleton.names[j], str(len(sw)), f"{mlen:.3f}", f"{mang:.1f}", str(len(seg.holds_of(j))))
    out.print(table)
    if facts["segmentation_error"] is not None:
        out.print(f"  Segmentation Error {facts['segmentation_error']:.2f} deg "
                  f"({facts['per_angle_error_deg']:.3f} deg per angle, the paper's measure); "
                  f"geodesic {facts['geodesic_error_deg']:.2f} deg per joint")
    out.print(f"  compressed {facts['compressed_bytes']} bytes = {size['ratio_raw']:.3f} of the raw float32 "
              f"channels ({facts['raw_float32_bytes']} bytes)"
              + (f", {size['ratio_bvh']:.3f} of the BVH text" if size["ratio_bvh"] else ""))
    out.print(f"  {seconds:.3f} s")


@app.command()
@friendly
def search(
    query: Annotated[Path, typer.Argument(help="The example take (.bvh or .amc).")],
    folder: Annotated[Path, typer.Argument(help="Folder of takes to search.")],
    top: Annotated[int, typer.Option(help="How many matches to print.")] = 10,
    pattern: Annotated[str, typer.Option(help="File pattern in the folder.")] = "*.bvh",
    threshold: Annotated[float, typer.Option(help=_THRESHOLD_HELP)] = 0.4,
    window: Annotated[float, typer.Option(help="Sliding window length, seconds.")] = 1.0,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
):
    """Rank the takes of a folder by how alike their swings are to an example (query by example)."""
    from ..swings import build_index

    if top < 1:
        raise MocycleError(f"--top must be >= 1; got {top}")
    t0 = time.perf_counter()
    motion = read(query, fps=fps)
    index = build_index(folder, pattern=pattern, threshold=threshold, window_s=window)
    hits = index.query(motion, top=top, exclude=query)
    seconds = time.perf_counter() - t0
    if as_json:
        print(json_text({"query": str(query), "indexed": len(index), "seconds": seconds,
                          "results": [{"rank": k + 1, "path": str(h.path), "score": h.score,
                                       "offset_s": h.offset_s} for k, h in enumerate(hits)]}, indent=2))
        return
    table = Table(title=f"{query.name} against {len(index)} takes in {folder}")
    for col in ("rank", "score", "offset s", "take"):
        table.add_column(col, justify="left" if col == "take" else "right")
    for k, h in enumerate(hits):
        table.add_row(str(k + 1), f"{h.score:.3f}", f"{h.offset_s:+.2f}", h.path.name)
    out.print(table)
    out.print(f"  {seconds:.2f} s")


@app.command()
@friendly
def edit(
    path: Annotated[Path, typer.Argument(help="A .bvh or .amc file.")],
    joint: Annotated[str, typer.Option(help="Joint whose swing to edit (exact name).")],
    swing: Annotated[int, typer.Option(help="Which swing of the joint, 0-based in time order "
                                            "(see `mocycle swings IN`).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Edited motion (.bvh).")],
    angle_scale: Annotated[float, typer.Option(help="Scale of the angle the swing turns through (0-10).")] = 1.0,
    duration_scale: Annotated[float, typer.Option(help="Scale of the swing's length in time (0.05-20).")] = 1.0,
    threshold: Annotated[float, typer.Option(help=_THRESHOLD_HELP)] = 0.4,
    joints: Annotated[str | None, typer.Option(help=_JOINTS_HELP)] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Scale the angle or the duration of one swing of one joint and write the edited motion."""
    from ..swings import edit_swing, segment

    check_output(output, [path], force, ".bvh")
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    seg = segment(motion, threshold=threshold, joints=joints)
    j = motion.skeleton.index(joint)
    if j not in seg.joints and joints is None:
        seg = segment(motion, threshold=threshold, joints=sorted({*(motion.skeleton.names[k] for k in seg.joints),
                                                                  joint}))
    edited = edit_swing(motion, seg, joint, swing, angle_scale=angle_scale, duration_scale=duration_scale)
    write(edited, output)
    sw = seg.swings_of(joint)[swing]
    facts = {"joint": joint, "swing": swing, "start": sw.start, "end": sw.end,
             "angle_deg": abs(sw.end_angle - sw.start_angle) * 57.29577951308232, "angle_scale": angle_scale,
             "duration_scale": duration_scale, "output": str(output), "seconds": time.perf_counter() - t0}
    if as_json:
        print(json_text(facts))
    else:
        out.print(f"{joint} swing {swing} (frames {sw.start}-{sw.end}, {facts['angle_deg']:.1f} deg): "
                  f"angle x{angle_scale:g}, duration x{duration_scale:g} -> {output}")
