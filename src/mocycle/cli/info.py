"""``mocycle info``: the facts of a take."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from ..io import read_motion as read
from ..io.bvh import motion_channels
from ..motion import Motion
from .common import app, friendly, json_text, out


def motion_info(motion: Motion) -> dict:
    """The facts ``mocycle info`` prints, as a JSON-ready dict."""
    skel = motion.skeleton
    travel = motion.travel_joint
    root = motion.world_positions()[:, travel]
    steps = np.linalg.norm(np.diff(root, axis=0), axis=1) if motion.n_frames > 1 else np.zeros(0)
    values = motion_channels(motion)
    ranges: dict[str, dict[str, float]] = {}
    spread: dict[str, float] = {}
    col = 0
    for j, name in enumerate(skel.names):
        per = {}
        for c in skel.channels[j]:
            if c.endswith("rotation"):
                per[c] = float(np.ptp(values[:, col]))
            col += 1
        if per:
            ranges[name] = per
            r = motion.rotation(j)
            spread[name] = float(np.degrees((r.mean().inv() * r).magnitude().max()))
    return {
        "frames": motion.n_frames,
        "frame_time": motion.frame_time,
        "fps": motion.fps,
        "duration_s": motion.duration,
        "joints": skel.n_joints,
        "channels": skel.n_channels,
        "end_sites": len(skel.end_sites),
        "travel_joint": skel.names[travel],
        "root_start": root[0].tolist(),
        "root_end": root[-1].tolist(),
        "root_displacement": float(np.linalg.norm(root[-1] - root[0])),
        "root_path_length": float(steps.sum()),
        "rotation_range_deg": ranges,
        "rotation_spread_deg": spread,
    }


@app.command()
@friendly
def info(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON instead of tables.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
):
    """Frames, frame time, fps, duration, joints, channels, root travel and rotation ranges."""
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    facts = motion_info(motion)
    facts["file"] = str(path)
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        print(json_text(facts))
        return
    _print_info(facts)


def _print_info(facts: dict) -> None:
    out.print(f"[bold]{facts['file']}[/]")
    out.print(
        f"  {facts['frames']} frames × {facts['frame_time']:.6g} s = {facts['duration_s']:.3f} s "
        f"({facts['fps']:.6g} fps)\n"
        f"  {facts['joints']} joints, {facts['channels']} channels, {facts['end_sites']} end sites\n"
        f"  travel of {facts['travel_joint']}: {facts['root_displacement']:.4g} net, "
        f"{facts['root_path_length']:.4g} along the path (file units)"
    )
    ranges, spread = facts["rotation_range_deg"], facts["rotation_spread_deg"]
    order = sorted(spread, key=lambda n: -spread[n])
    shown = order if len(order) <= 40 else order[:20]
    table = Table(title="rotation per joint (degrees)")
    table.add_column("joint")
    table.add_column("max angle from mean pose", justify="right")
    table.add_column("channel ranges (max - min; large near gimbal lock)")
    for name in shown:
        table.add_row(name, f"{spread[name]:.1f}", "  ".join(f"{c[0]} {v:6.1f}" for c, v in ranges[name].items()))
    out.print(table)
    if len(shown) < len(order):
        out.print(f"  ({len(order) - len(shown)} more joints; --json lists all)")


