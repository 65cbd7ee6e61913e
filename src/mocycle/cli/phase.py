"""``mocycle phase``: periodic motions and the phase of every frame."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import (
    EXIT_NOT_FOUND,
    check_output,
    err,
    escape,
    out,
    print_json,
    print_warnings,
    task_command,
    timing_line,
)


@task_command("phase")
def phase(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: diagram, phase per frame, PCA by phase.")] = None,
    *, options, as_json, force,
):
    """Find periodic motions and the phase of every frame (persistent cohomology).

    Exit code 0 when at least one periodic motion is found, 3 when none is
    (the reason is printed), 1 for bad input, 2 for a bad option.
    """
    check_output(plot, [path], force, ".png", "--plot")
    report = tasks.phase.run(path, options, keep_features=plot is not None)
    print_warnings(report)
    if plot is not None:
        from ..viz import plot_phase

        plot_phase(report.result, plot, title=path.name)
    facts = {**report.facts, "seconds": report.seconds}
    if as_json:
        print_json(facts)
    else:
        _print_phase(path, report)
        if plot is not None:
            out.print(f"wrote {escape(plot)}", soft_wrap=True)
    if not report.facts["classes"]:
        err.print(f"no periodic motion found: {escape(report.facts['reason'])}", soft_wrap=True)
        raise typer.Exit(EXIT_NOT_FOUND)


def _print_phase(path: Path, report) -> None:
    from rich.table import Table

    facts = report.facts
    out.print(f"[bold]{escape(path)}[/]: {facts['frames']} frames at {facts['fps']:.6g} fps")
    table = Table(title="periodic motions (H1 classes)")
    for col in ("class", "bar [birth, death)", "period frames", "period s", "periods", "excitation frames"):
        table.add_column(col, justify="right" if col != "excitation frames" else "left")
    for k, c in enumerate(facts["classes"]):
        table.add_row(str(k), f"[{c['birth']:.3g}, {c['death']:.3g})", f"{c['period_frames']:.2f}",
                      f"{c['period_s']:.3f}", f"{c['n_periods']:.2f}",
                      ", ".join(f"{s}-{e}" for s, e in c["excitation"]))
    if facts["classes"]:
        out.print(table)
    acf = facts["autocorrelation_period_frames"]
    out.print(f"  autocorrelation period (cross-check): {'none' if acf is None else f'{acf:.2f} frames'}")
    legs = facts["legs_period_frames"]
    out.print(f"  legs' autocorrelation period: {'none' if legs is None else f'{legs:.2f} frames'}; "
              f"joints used: {escape(facts['joints_used'])}", soft_wrap=True)
    for k, c in enumerate(facts["classes"]):
        out.print(f"  class {k} period: {escape(c['period_reason'])}", soft_wrap=True)
    out.print(f"  why: {escape(facts['reason'])}", soft_wrap=True)
    out.print(timing_line(report))
