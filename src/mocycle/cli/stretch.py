"""``mocycle stretch``: lengthen a take by time-frequency warping (paper 004), keeping its cycle."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import check_output, delivered, escape, out, print_closing, print_feet, print_json, task_command


@task_command("stretch")
def stretch(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: the most moving joint curves of the input and the stretched take in seconds.")] = None,
    *, options, output, as_json, force, write,
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
    check_output(plot, [path], force, ".png", "--plot")
    report = delivered(tasks.stretch.run(path, options), write)
    if plot is not None:
        from ..viz import plot_curves

        series = [("stretched", report.motions["stretched"], None), ("input", report.motions["input"], None)]
        plot_curves(series, plot, title=f"{path.name} stretched × {options.factor:g}: cycles copied, not slowed down")
    facts = {**{k: v for k, v in report.facts.items() if k not in ("fps", "joints_per_group")},
             "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    from rich.table import Table

    from ..warp.stretch import StretchReport

    r = report.facts
    stretched = report.result
    assert isinstance(stretched, StretchReport)  # what tasks.stretch makes
    out.print(f"[bold]{escape(path)}[/]: {r['frames_in']} frames -> {escape(output)}: {r['frames_out']} frames "
              f"(factor {r['factor']:g}, {r['fps']:.6g} fps)", soft_wrap=True)
    table = Table(title="windows (frames)")
    for col in ("group", "window", "cycle found", "joints"):
        table.add_column(col, justify="left" if col in ("group", "joints") else "right")
    for g, n in r["windows"].items():
        cycle = stretched.cycles[g]
        table.add_row(escape(g), str(n), "given" if cycle is None else f"{cycle:.2f}", str(r["joints_per_group"][g]))
    out.print(table)
    if r["periodic_regions"]:
        kept = r["frames_in"] - sum(e - s for s, e in r["periodic_regions"])
        out.print("  periodic region(s) warped: " + ", ".join(
            f"{s}:{e} -> {a}:{b}" for (s, e), (a, b) in zip(r["periodic_regions"], r["periodic_regions_out"],
                                                             strict=True))
            + (f"; {kept} frame(s) kept as captured" if kept else ""), soft_wrap=True)
    print_feet(r["feet"])
    if r["trend_curves"]:
        out.print(f"  warped as line + residual: {escape(', '.join(r['trend_curves']))}", soft_wrap=True)
    print_closing(report, plot)
