"""``mocycle loop``: one seamless typical cycle of a take, written as BVH."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.table import Table

from ..errors import MocycleError
from ..io import read_motion as read
from ..io import write
from .common import (
    ClassesOption,
    DelayOption,
    JointsOption,
    MinPeriodsOption,
    PcaOption,
    app,
    check_output,
    count_option,
    friendly,
    json_text,
    out,
    parse_range,
    phase_options,
)
from .feet import FEET_HELP, FOOT_JOINTS_HELP, check_feet_mode, clean_feet

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
    "skate": ("foot skate, cycle (as fitted)", "units/s"),
    "input_skate": ("foot skate, input", "units/s"),
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
    joints: JointsOption = None,
    cycles: Annotated[int, typer.Option(help="Repeat the cycle this many times in the output.")] = 1,
    classes: ClassesOption = "auto",
    which: Annotated[str | None, typer.Option(
        "--class", help="Which periodic motion to loop (0-based; default: the one covering most frames), or "
                        "'all': one file per periodic motion, OUT.class0.bvh, OUT.class1.bvh, ...")] = None,
    pca: PcaOption = "auto",
    delay: DelayOption = 2,
    min_periods: MinPeriodsOption = 1.2,
    time_axis: Annotated[str, typer.Option(
        "--time", help="Phase to time: smooth (default), rank (thesis eq. 3.20), gmm (eq. 3.21) or line.")]
    = "smooth",
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: PCA of input and cycle, phase, joint curves.")]
    = None,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option(
        "--force", help="Write the cycle even when it fails a loop check (longer than the take, fits much "
                        "worse than a plain cut, seam jumps); a warning names the check. It also lets an output "
                        "replace an input file.")] = False,
    feet: Annotated[str, typer.Option(help=FEET_HELP)] = "auto",
    feet_plot: Annotated[Path | None, typer.Option(
        help="Write a PNG of the contacts: each ankle and toe's height and speed over two cycles, before (dashed) "
             "and after locking.")] = None,
    foot_joints: Annotated[str | None, typer.Option(help=FOOT_JOINTS_HELP)] = None,
):
    """Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH.

    Exit code 0 on success, 3 when the take holds no periodic motion or its cycle fails a loop check
    (the reason is printed; --force writes it anyway), 1 for bad input.
    """
    from ..cycle import cycle_phase, extract_cycle, loop_metrics
    from ..cycle.checks import check_loop

    check_output(output, [path], force, ".bvh", "--output")
    check_output(plot, [path], force, ".png", "--plot")
    check_output(feet_plot, [path], force, ".png", "--feet-plot")
    if cycles < 1:
        raise MocycleError(f"--cycles must be a positive integer; got {cycles}")
    check_feet_mode(feet)
    everything = which == "all"
    chosen = None if which is None or everything else _class_number(which)
    options = phase_options(joints, classes, pca, delay, min_periods)
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    start, stop = parse_range(frame_range, motion.n_frames)
    motion = motion[start:stop]
    phase = cycle_phase(motion, phase_step=step, **options)
    targets = [(k, output.with_suffix(f".class{k}.bvh")) for k in range(len(phase.classes))] if everything \
        else [(chosen, output)]
    if everything and not targets:
        targets = [(None, output)]  # extract_cycle says why there is nothing to loop
    made, metrics_seconds = [], 0.0
    for k, target in targets:  # every cycle is made and checked before any file is written
        cycle = extract_cycle(
            motion, method=method, model=model,
            n_harmonics=count_option(harmonics, "--harmonics", {"auto": "auto"}), time_axis_method=time_axis,
            which=k, phase=phase)
        fitted = cycle
        cycle, feet_facts, contacts = clean_feet(cycle, feet, root, foot_joints)
        if feet_plot is not None and contacts is None:  # refused before any file is written
            raise MocycleError("--feet-plot needs locked feet (--feet lock, or auto with --root motion)")
        t1 = time.perf_counter()
        # the metrics and checks judge the fitted cycle against the take (locking changes the legs on
        # purpose); the feet block says what locking did
        metrics = loop_metrics(motion, fitted)
        label = f"{path} class {k}" if everything else str(path)
        failed = check_loop(motion, fitted, metrics, force=force, label=label)
        metrics_seconds += time.perf_counter() - t1
        made.append((target, cycle, cycle.repeat(cycles, root=root), metrics, failed, fitted, feet_facts, contacts))
    seconds = time.perf_counter() - t0 - metrics_seconds
    reports = []
    for target, cycle, result, metrics, failed, fitted, feet_facts, contacts in made:
        write(result, target)
        k = next(i for i, c in enumerate(phase.classes) if c is cycle.periodic)
        if feet_plot is not None:
            _plot_feet(fitted, cycle, contacts, feet_plot.with_suffix(f".class{k}.png") if everything else feet_plot,
                       f"{path.name}: feet locked")
        if plot is not None:
            from ..viz import plot_loop

            image = plot.with_suffix(f".class{k}.png") if everything else plot
            plot_loop(motion, cycle, image,
                      title=f"{path.name}: {method}{' ' + model if method == 'harmonic' else ''}")
        reports.append({
            "file": str(path),
            "output": str(target),
            "class": k,
            "frames_in": motion.n_frames,
            "frames_out": result.n_frames,
            "fps": motion.fps,
            **cycle.to_dict(),
            "excitation": [[int(s), int(e)] for s, e in cycle.axis.regions],
            "model": model if method == "harmonic" else None,
            "root": root,
            "cycles": cycles,
            "metrics": metrics,
            "failed_checks": [f.to_dict() for f in failed],
            "feet": feet_facts,
            "seconds": seconds,
            "metrics_seconds": metrics_seconds,
        })
    if as_json:
        print(json_text({"file": str(path), "loops": reports} if everything else reports[0]))
        return
    for facts, (_, cycle, *_) in zip(reports, made, strict=True):
        _print_loop(facts, len(cycle.periodic.excitation), which)


def _plot_feet(fitted, cycle, contacts, image: Path, title: str) -> None:
    """The contacts plot over two cycles of the locked loop, the fitted one dashed."""
    from ..contacts import Contacts
    from ..viz import plot_contacts

    twice = Contacts(contacts.feet, contacts.joints, contacts.foot_of, np.tile(contacts.mask, (2, 1)), contacts.up,
                     contacts.body, contacts.frame_time)
    plot_contacts(cycle.repeat(2, root="motion"), twice, image, title=title, before=fitted.repeat(2, root="motion"))


def _class_number(text: str) -> int:
    try:
        k = int(text)
    except ValueError:
        k = -1
    if k < 0:
        raise MocycleError(f"--class must be a class number (0, 1, ...) or 'all'; got {text!r}")
    return k


def _print_loop(facts: dict, n_regions: int, which: int | None) -> None:
    kind = facts["method"] + (f" {facts['model']}, K = {facts['harmonics']}" if facts["method"] == "harmonic" else "")
    out.print(f"[bold]{facts['file']}[/]: {facts['frames_in']} frames at {facts['fps']:.6g} fps")
    out.print(f"  class {facts['class']}: {facts['n_periods']:.2f} periods of {facts['period_frames']:.2f} frames "
              f"(time axis: {facts['time_axis']}, {n_regions} excited region(s): "
              + ", ".join(f"{s}-{e}" for s, e in facts["excitation"]) + f"; joints used: {facts['joints_used']})")
    out.print(f"  period: {facts['period_reason']}", soft_wrap=True)
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
    f = facts["feet"]
    if f["mode"] == "lock":
        spans = "; ".join(f"{side} {' '.join(f'{a}-{b}' for a, b in v['contacts'])}" for side, v in
                          f["contacts"].items())
        out.print(f"  feet locked (contacts, cycle frames: {spans}); skate {f['skate_before']:.4g} -> "
                  f"{f['skate_after']:.4g} units/s in {f['seconds']:.2f} s")
    out.print(f"wrote {facts['output']}: {facts['frames_out']} frames ({facts['cycles']} cycle(s), root "
              f"{facts['root']}) in {facts['seconds']:.2f} s")
