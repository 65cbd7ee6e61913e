"""``mocycle info``: the facts of a take."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import delivered, escape, out, print_json, task_command


@task_command("info")
def info(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    *, options, as_json,
):
    """Frames, frame time, fps, duration, joints, channels, root travel and rotation ranges."""
    report = delivered(tasks.info.run(path, options))
    facts = {**report.facts, "file": str(path), "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    _print_info(facts)


def _print_info(facts: dict) -> None:
    from rich.table import Table

    out.print(f"[bold]{escape(facts['file'])}[/]", soft_wrap=True)
    out.print(
        f"  {facts['frames']} frames × {facts['frame_time']:.6g} s = {facts['duration_s']:.3f} s "
        f"({facts['fps']:.6g} fps)\n"
        f"  {facts['joints']} joints, {facts['channels']} channels, {facts['end_sites']} end sites\n"
        f"  travel of {escape(facts['travel_joint'])}: {facts['root_displacement']:.4g} net, "
        f"{facts['root_path_length']:.4g} along the path (file units)"
        + (f"\n  takes: {', '.join(facts['takes'])} (read: {facts['take']})" if "takes" in facts else "")
    )
    ranges, spread = facts["rotation_range_deg"], facts["rotation_spread_deg"]
    order = sorted(spread, key=lambda n: -spread[n])
    shown = order if len(order) <= 40 else order[:20]
    table = Table(title="rotation per joint (degrees)")
    table.add_column("joint")
    table.add_column("max angle from mean pose", justify="right")
    table.add_column("channel ranges (max - min; large near gimbal lock)")
    for name in shown:
        table.add_row(escape(name), f"{spread[name]:.1f}",
                      "  ".join(f"{c[0]} {v:6.1f}" for c, v in ranges[name].items()))
    out.print(table)
    if len(shown) < len(order):
        out.print(f"  ({len(order) - len(shown)} more joints; --json lists all)")
