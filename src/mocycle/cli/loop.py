"""``mocycle loop``: one seamless typical cycle of a take, written as BVH."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from ..io import write
from ..tasks.loop import METRIC_LABELS
from .common import app, check_suffix, default, flag, friendly, out, print_json, print_warnings, timing_line

O = tasks.loop.Options


@app.command()
@friendly
def loop(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The cycle as a .bvh file.")],
    method: Annotated[str, flag(O, "method")] = default(O, "method"),
    model: Annotated[str, flag(O, "model")] = default(O, "model"),
    harmonics: Annotated[str, flag(O, "harmonics")] = default(O, "harmonics"),
    root: Annotated[str, flag(O, "root")] = default(O, "root"),
    frame_range: Annotated[str | None, flag(O, "frame_range")] = default(O, "frame_range"),
    step: Annotated[int, flag(O, "step")] = default(O, "step"),
    joints: Annotated[str | None, flag(O, "joints")] = default(O, "joints"),
    cycles: Annotated[int, flag(O, "cycles")] = default(O, "cycles"),
    classes: Annotated[str, flag(O, "classes")] = default(O, "classes"),
    which: Annotated[int | None, flag(O, "which")] = default(O, "which"),
    time_axis: Annotated[str, flag(O, "time_axis")] = default(O, "time_axis"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: PCA of input and cycle, phase, joint curves.")]
    = None,
    amc_fps: Annotated[float, flag(O, "amc_fps")] = default(O, "amc_fps"),
    force: Annotated[bool, flag(O, "force")] = default(O, "force"),
):
    """Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH.

    Exit code 0 on success, 3 when the take holds no periodic motion or its cycle fails a loop check
    (the reason is printed; --force writes it anyway), 1 for bad input, 2 for a bad option.
    """
    check_suffix(output, ".bvh", "--output")
    check_suffix(plot, ".png", "--plot")
    options = O(method=method, model=model, harmonics=harmonics, root=root, frame_range=frame_range, step=step,
                joints=joints, cycles=cycles, classes=classes, which=which, time_axis=time_axis, amc_fps=amc_fps,
                force=force)
    report = tasks.loop.run(path, options)
    print_warnings(report)
    write(report.motions["loop"], output)
    if plot is not None:
        from ..viz import plot_loop

        plot_loop(report.motions["input"], report.result, plot,
                  title=f"{path.name}: {method}{' ' + model if method == 'harmonic' else ''}")
    facts = {"file": str(path), "output": str(output), **report.facts, "seconds": report.seconds,
             "metrics_seconds": report.timings_s["metrics"]}
    if as_json:
        print_json(facts)
        return
    _print_loop(facts, report)
    if plot is not None:
        out.print(f"wrote {plot}", soft_wrap=True)


def _print_loop(facts: dict, report) -> None:
    from rich.table import Table

    kind = facts["method"] + (f" {facts['model']}, K = {facts['harmonics']}" if facts["method"] == "harmonic" else "")
    out.print(f"[bold]{facts['file']}[/]: {facts['frames_in']} frames at {facts['fps']:.6g} fps")
    out.print(f"  {facts['n_periods']:.2f} periods of {facts['period_frames']:.2f} frames "
              f"(time axis: {facts['time_axis']}, {facts['excited_regions']} excited region(s))")
    move = facts["travel_per_cycle"]
    out.print(f"  cycle: {facts['cycle_frames']} frames by {kind}; travel per cycle "
              f"({move[0]:.3g}, {move[1]:.3g}, {move[2]:.3g}), turn {facts['turn_per_cycle_deg']:.3g}°")
    table = Table(title="loop metrics")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for key, (label, unit) in METRIC_LABELS.items():
        table.add_row(label, f"{facts['metrics'][key]:.4g}", unit)
    out.print(table)
    out.print(f"wrote {facts['output']}: {facts['frames_out']} frames ({facts['cycles']} cycle(s), root "
              f"{facts['root']})", soft_wrap=True)
    out.print(timing_line(report))
