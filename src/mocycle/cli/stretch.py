"""``mocycle stretch``: lengthen a take by time-frequency warping (paper 004), keeping its cycle."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ..io import read_motion as read
from ..io import write
from .common import (
    app,
    check_output,
    count_option,
    friendly,
    json_text,
    out,
)
from .feet import FEET_HELP, FOOT_JOINTS_HELP, check_feet_mode, lock_motion, travels


@app.command()
@friendly
def stretch(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    factor: Annotated[float, typer.Option(help="Length ratio: 2 doubles the take (frames out = round(frames * F)).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The .bvh file to write.")],
    window: Annotated[str, typer.Option(
        help="Block length in frames: 'auto' (each joint group's largest fundamental cycle) or N.")] = "auto",
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option(
        "--force", help="Warp the whole take even when it has no periodic motion (a warning says so). It also "
                        "lets an output replace an input file.")] = False,
    feet: Annotated[str, typer.Option(help=FEET_HELP.replace("with --root motion", "when the take travels"))]
    = "auto",
    foot_joints: Annotated[str | None, typer.Option(help=FOOT_JOINTS_HELP)] = None,
):
    """Lengthen a take by time-frequency warping: its cycles are replicated, not slowed down.

    Only the periodic region(s) of the take (its phase's excitation regions) are
    warped; a lead-in, pauses and a lead-out are kept as captured and follow on
    without a pop. The lapped cosine transform of every joint curve is dilated
    in time by replicating its atoms (paper 004); each joint group (legs, arms,
    spine) uses its own fundamental cycle as the window; the travelling joint
    keeps its mean velocity. Exit code 3 when the take has no periodic motion
    (--force warps it whole anyway), 1 for bad input.
    """
    from ..warp import stretch_motion

    check_output(output, [path], force, ".bvh")
    win = count_option(window, "--window", {"auto": "auto"})
    check_feet_mode(feet)
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    result, report = stretch_motion(motion, factor, window=win, force=force)
    result, feet_facts = lock_motion(result, feet, foot_joints, travels(motion))
    write(result, output)
    facts = report.to_dict()
    facts["feet"] = feet_facts
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        print(json_text(facts))
        return
    out.print(f"[bold]{path}[/]: {report.frames_in} frames -> {output}: {report.frames_out} frames "
              f"(factor {report.factor:g}, {motion.fps:.6g} fps)", soft_wrap=True)
    table = Table(title="windows (frames)")
    for col in ("group", "window", "cycle found", "joints"):
        table.add_column(col, justify="left" if col in ("group", "joints") else "right")
    for g, n in report.windows.items():
        cycle = report.cycles[g]
        table.add_row(g, str(n), "given" if cycle is None else f"{cycle:.2f}", str(len(report.groups[g])))
    out.print(table)
    if report.regions:
        kept = report.frames_in - sum(e - s for s, e in report.regions)
        out.print("  periodic region(s) warped: " + ", ".join(
            f"{s}:{e} -> {a}:{b}" for (s, e), (a, b) in zip(report.regions, report.regions_out, strict=True))
            + (f"; {kept} frame(s) kept as captured" if kept else ""), soft_wrap=True)
    if report.trend_curves:
        out.print(f"  warped as line + residual: {', '.join(report.trend_curves)}", soft_wrap=True)
    if feet_facts["mode"] == "lock":
        out.print(f"  feet locked: skate {feet_facts['skate_before']:.4g} -> {feet_facts['skate_after']:.4g} units/s")
    out.print(f"  {facts['seconds']:.3f} s")
