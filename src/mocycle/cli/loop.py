"""``mocycle loop``: one seamless typical cycle of a take, written as BVH."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from ..errors import MocycleError
from ..io import read, write
from .common import FORCE_HELP, app, check_output, count_option, friendly, json_text, out, parse_range

METRIC_LABELS = {
    "template_error": ("template error", "rad"),
    "rmse_h": ("RMSE h", "rad"),
    "rmse_dh": ("RMSE h'", "rad/s"),
    "rmse_ddh": ("RMSE h''", "rad/s²"),
    "jerk_ratio": ("jerk, cycle / input", ""),
    "seam_pose": ("seam jump, pose", "× median step"),
    "seam_velocity": ("seam jump, velocity", "× median change"),
    "seam_pose_local": ("seam jump, pose (local)", "× nearby steps"),
    "seam_velocity_local": ("seam jump, velocity (local)", "× nearby changes"),
    "foot_sliding": ("foot sliding, cycle", "units/s"),
    "input_foot_sliding": ("foot sliding, input", "units/s"),
}


@app.command()
@friendly
def loop(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The cycle as a .bvh file.")],
    method: Annotated[str, typer.Option(help="harmonic (regression), centroid (paper 001) or cut (baseline).")]
    = "harmonic",
    model: Annotated[str, typer.Option(
        help="Harmonic model: M1 (FGLS-weighted positions, velocities, accelerations), M2 (positions only; "
             "velocity/acceleration off), M3 (unweighted).")] = "M1",
    harmonics: Annotated[str, typer.Option(help="Harmonics K: 'auto' (20, capped by the frames) or a number.")]
    = "auto",
    root: Annotated[str, typer.Option(help="inplace (walks on the spot, facing kept) or motion (moves on).")]
    = "inplace",
    frame_range: Annotated[str | None, typer.Option("--range", help="Use frames START:STOP of the take.")] = None,
    step: Annotated[int, typer.Option(help="Find the phase on every STEP-th frame (faster on long takes).")] = 1,
    joints: Annotated[str | None, typer.Option(
        help="Joints to find the phase on (names, globs, legs/arms/spine); every joint is looped.")] = None,
    cycles: Annotated[int, typer.Option(help="Repeat the cycle this many times in the output.")] = 1,
    classes: Annotated[str, typer.Option(help="How many periodic motions to look for: 'auto' or N.")] = "auto",
    which: Annotated[int | None, typer.Option(
        "--class", help="Which periodic motion to loop (0-based; default: the one covering most frames).")] = None,
    time_axis: Annotated[str, typer.Option(
        "--time", help="Phase to time: smooth (default), rank (thesis eq. 3.20), gmm (eq. 3.21) or line.")]
    = "smooth",
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: PCA of input and cycle, phase, joint curves.")]
    = None,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH.

    Exit code 0 on success, 3 when the take holds no periodic motion, 1 for bad input.
    """
    from ..cycle import extract_cycle, loop_metrics

    check_output(output, [path], force, ".bvh", "--output")
    check_output(plot, [path], force, ".png", "--plot")
    if cycles < 1:
        raise MocycleError(f"--cycles must be a positive integer; got {cycles}")
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    start, stop = parse_range(frame_range, motion.n_frames)
    motion = motion[start:stop]
    cycle = extract_cycle(
        motion, method=method, model=model, n_harmonics=count_option(harmonics, "--harmonics", {"auto": "auto"}),
        time_axis_method=time_axis, joints=joints, classes=count_option(classes, "--classes", {"auto": "auto"}),
        which=which, phase_step=step)
    result = cycle.repeat(cycles, root=root)
    write(result, output)
    seconds = time.perf_counter() - t0
    t1 = time.perf_counter()
    metrics = loop_metrics(motion, cycle)
    metrics_seconds = time.perf_counter() - t1
    if plot is not None:
        from ..viz import plot_loop

        plot_loop(motion, cycle, plot, title=f"{path.name}: {method}{' ' + model if method == 'harmonic' else ''}")
    facts = {
        "file": str(path),
        "output": str(output),
        "frames_in": motion.n_frames,
        "frames_out": result.n_frames,
        "fps": motion.fps,
        **cycle.to_dict(),
        "model": model if method == "harmonic" else None,
        "root": root,
        "cycles": cycles,
        "metrics": metrics,
        "seconds": seconds,
        "metrics_seconds": metrics_seconds,
    }
    if as_json:
        print(json_text(facts))
        return
    _print_loop(facts, len(cycle.periodic.excitation), which)


def _print_loop(facts: dict, n_regions: int, which: int | None) -> None:
    kind = facts["method"] + (f" {facts['model']}, K = {facts['harmonics']}" if facts["method"] == "harmonic" else "")
    out.print(f"[bold]{facts['file']}[/]: {facts['frames_in']} frames at {facts['fps']:.6g} fps")
    out.print(f"  {facts['n_periods']:.2f} periods of {facts['period_frames']:.2f} frames "
              f"(time axis: {facts['time_axis']}, {n_regions} excited region(s))")
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
              f"{facts['root']}) in {facts['seconds']:.2f} s")
