"""``mocycle phase``: periodic motions and the phase of every frame."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ..errors import MocycleError
from ..io import read
from .common import EXIT_NOT_FOUND, FORCE_HELP, app, check_output, count_option, err, friendly, json_text, out


@app.command()
@friendly
def phase(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    classes: Annotated[str, typer.Option(help="Number of periodic motions: 'auto' or N.")] = "auto",
    joints: Annotated[str | None, typer.Option(
        help="Joints to use: names, glob patterns or groups (legs, arms, spine), comma-separated.")] = None,
    pca: Annotated[str, typer.Option(help="PCA dimensions before the cohomology: 'auto' (8), N or 'none'.")] = "auto",
    delay: Annotated[int, typer.Option(help="Delay embedding factor m (KTH thesis eq. 3.26; it used 2).")] = 2,
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
    if delay < 0:
        raise MocycleError(f"--delay must be >= 0; got {delay}")
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    result = find_phase(motion, classes=count_option(classes, "--classes", {"auto": "auto"}), joints=joints,
                        pca=count_option(pca, "--pca", {"auto": "auto", "none": None, "0": None}),
                        delay=delay, n_landmarks=landmarks)
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
    out.print(f"  why: {facts['reason']}", soft_wrap=True)
    out.print(f"  {facts['seconds']:.3f} s")


