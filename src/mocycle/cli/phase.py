"""``mocycle phase``: periodic motions and the phase of every frame."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ..io import read_motion as read
from .common import (
    EXIT_NOT_FOUND,
    FORCE_HELP,
    ClassesOption,
    DelayOption,
    JointsOption,
    MinPeriodsOption,
    PcaOption,
    app,
    check_output,
    err,
    friendly,
    json_text,
    out,
    phase_options,
)


@app.command()
@friendly
def phase(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    classes: ClassesOption = "auto",
    joints: JointsOption = None,
    pca: PcaOption = "auto",
    delay: DelayOption = 2,
    min_periods: MinPeriodsOption = 1.2,
    landmarks: Annotated[int, typer.Option(help="Landmarks for the Rips filtration.")] = 120,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: diagram, phase per frame, PCA by phase.")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
):
    """Find periodic motions and the phase of every frame (persistent cohomology).

    Exit code 0 when at least one periodic motion is found, 3 when none is
    (the reason is printed), 1 for bad input.
    """
    from ..phase import find_phase

    check_output(plot, [path], force, ".png", "--plot")
    options = phase_options(joints, classes, pca, delay, min_periods)
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    result = find_phase(motion, n_landmarks=landmarks, keep_features=plot is not None, **options)
    if plot is not None:
        from ..viz import plot_phase

        plot_phase(result, plot, title=path.name)
    facts = result.to_dict()
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        print(json_text(facts))
    else:
        _print_phase(path, facts)
    if not result.classes:
        err.print(f"no periodic motion found: {result.reason}", soft_wrap=True)
        raise typer.Exit(EXIT_NOT_FOUND)


def _print_phase(path: Path, facts: dict) -> None:
    out.print(f"[bold]{path}[/]: {facts['frames']} frames at {facts['fps']:.6g} fps")
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
              f"joints used: {facts['joints_used']}")
    for k, c in enumerate(facts["classes"]):
        out.print(f"  class {k} period: {c['period_reason']}", soft_wrap=True)
    out.print(f"  why: {facts['reason']}", soft_wrap=True)
    out.print(f"  {facts['seconds']:.3f} s")


