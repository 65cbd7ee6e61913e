"""``mocycle stretch``: lengthen a take by time-frequency warping (paper 004), keeping its cycle."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import (
    GLTF_SCALE,
    GLTF_UP,
    app,
    check_motion_output,
    check_output,
    default,
    escape,
    flag,
    friendly,
    out,
    print_json,
    print_warnings,
    timing_line,
    write_motion,
)

O = tasks.stretch.Options


@app.command()
@friendly
def stretch(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    factor: Annotated[float, flag(O, "factor")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The .bvh or .glb file to write.")],
    window: Annotated[str, flag(O, "window_frames")] = default(O, "window_frames"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: the most moving joint curves of the input and the stretched take in seconds.")] = None,
    amc_fps: Annotated[float, flag(O, "amc_fps")] = default(O, "amc_fps"),
    take: Annotated[str | None, flag(O, "take")] = default(O, "take"),
    force: Annotated[bool, flag(O, "force")] = default(O, "force"),
    feet: Annotated[str, flag(O, "feet")] = default(O, "feet"),
    foot_joints: Annotated[str | None, flag(O, "foot_joints")] = default(O, "foot_joints"),
    gltf_scale: Annotated[str, GLTF_SCALE] = "auto",
    gltf_up: Annotated[str, GLTF_UP] = "auto",
):
    """Lengthen a take by time-frequency warping: its cycles are replicated, not slowed down.

    Only the periodic region(s) of the take (its phase's excitation regions) are
    warped; a lead-in, pauses and a lead-out are kept as captured and follow on
    without a pop. The lapped cosine transform of every joint curve is dilated
    in time by replicating its atoms (paper 004); each joint group (legs, arms,
    spine) uses its own fundamental cycle as the window; the travelling joint
    keeps its mean velocity. Exit code 3 when the take has no periodic motion
    (--force warps it whole anyway), 1 for bad input, 2 for a bad option.
    """
    check_motion_output(output, [path], force, "--output", gltf_scale, gltf_up)
    check_output(plot, [path], force, ".png", "--plot")
    report = tasks.stretch.run(path, O(factor=factor, window_frames=window, amc_fps=amc_fps, take=take, force=force,
                                       feet=feet, foot_joints=foot_joints))
    print_warnings(report)
    write_motion(report, "stretched", output, gltf_scale, gltf_up)
    if plot is not None:
        from ..viz import plot_curves

        series = [("stretched", report.motions["stretched"], None), ("input", report.motions["input"], None)]
        plot_curves(series, plot, title=f"{path.name} stretched × {factor:g}: cycles copied, not slowed down")
    facts = {**{k: v for k, v in report.facts.items() if k not in ("fps", "joints_per_group")},
             "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    from rich.table import Table

    r = report.facts
    out.print(f"[bold]{escape(path)}[/]: {r['frames_in']} frames -> {escape(output)}: {r['frames_out']} frames "
              f"(factor {r['factor']:g}, {r['fps']:.6g} fps)", soft_wrap=True)
    table = Table(title="windows (frames)")
    for col in ("group", "window", "cycle found", "joints"):
        table.add_column(col, justify="left" if col in ("group", "joints") else "right")
    for g, n in r["windows"].items():
        cycle = report.result.cycles[g]
        table.add_row(escape(g), str(n), "given" if cycle is None else f"{cycle:.2f}", str(r["joints_per_group"][g]))
    out.print(table)
    if r["periodic_regions"]:
        kept = r["frames_in"] - sum(e - s for s, e in r["periodic_regions"])
        out.print("  periodic region(s) warped: " + ", ".join(
            f"{s}:{e} -> {a}:{b}" for (s, e), (a, b) in zip(r["periodic_regions"], r["periodic_regions_out"],
                                                             strict=True))
            + (f"; {kept} frame(s) kept as captured" if kept else ""), soft_wrap=True)
    if r["feet"]["mode"] == "lock":
        out.print(f"  feet locked: skate {r['feet']['skate_before']:.4g} -> {r['feet']['skate_after']:.4g} units/s")
    if r["trend_curves"]:
        out.print(f"  warped as line + residual: {escape(', '.join(r['trend_curves']))}", soft_wrap=True)
    if plot is not None:
        out.print(f"wrote {escape(plot)}", soft_wrap=True)
    out.print(timing_line(report))
