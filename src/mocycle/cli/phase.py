"""``mocycle phase``: periodic motions and the phase of every frame."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import EXIT_NOT_FOUND, check_output, delivered, err, escape, out, print_closing, print_json, task_command


@task_command("phase")
def phase(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: diagram, phase per frame, PCA by phase.")] = None,
    *, options, as_json, force,
):
    """Find the steady parts of a take and the periodic motion and phase of each part that repeats.

    The parts are the ones mocycle loop lists and loops: walks, turns and runs (their phase from the feet's
    landings), arms and other repeating motion (persistent cohomology inside the part), gestures, standing.

    Exit code 0 when at least one part repeats, 3 when none does (the reason is printed), 1 for bad input, 2 for
    a bad option.
    """
    check_output(plot, [path], force, ".png", "--plot")
    report = delivered(tasks.phase.run(path, options, keep_features=plot is not None))
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
    parts = facts["parts"]
    if len(parts) > 1:
        out.print(f"  {len(parts)} parts: " + "; ".join(f"{k} {escape(p['kind'])} {p['frames'][0]}-{p['frames'][1]}"
                                                       for k, p in enumerate(parts)), soft_wrap=True)
    table = Table(title="periodic motions, one per part that repeats")
    for col in ("part", "kind", "frames", "period frames", "period s", "periods", "period from"):
        table.add_column(col, justify="left" if col in ("kind", "period from") else "right")
    for c in facts["classes"]:
        table.add_row(str(c["part"]), escape(c["kind"]), f"{c['frames'][0]}-{c['frames'][1]}",
                      f"{c['period_frames']:.2f}", f"{c['period_s']:.3f}", f"{c['n_periods']:.2f}",
                      escape(c["period_source"]))
    if facts["classes"]:
        out.print(table)
    for c in facts["classes"]:
        out.print(f"  part {c['part']} period: {escape(c['period_reason'])}", soft_wrap=True)
    out.print(f"  why: {escape(facts['reason'])}", soft_wrap=True)
    print_closing(report)
