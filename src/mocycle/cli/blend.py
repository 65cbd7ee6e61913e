"""``mocycle blend`` and ``mocycle transition``: new loops from the cycles of several takes (paper 001 §4.5)."""

from __future__ import annotations

import time
from dataclasses import replace as dc_replace
from pathlib import Path
from typing import Annotated

import typer

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
    phase_options,
)
from .feet import FEET_HELP, FOOT_JOINTS_HELP, check_feet_mode, clean_feet, lock_motion

METHOD_HELP = "How each take's cycle is extracted: harmonic (regression), centroid (paper 001) or cut."
MODEL_HELP = "Harmonic model: M1, M2 or M3 (see mocycle loop)."
HARMONICS_HELP = "Harmonics K: 'auto' (20, capped by the frames) or a number."
WhichOption = Annotated[int | None, typer.Option(
    "--class", min=0, help="Which periodic motion of each take to use (0-based; default: the one covering most "
                           "frames).")]
FORCE_HELP = ("Use a take's cycle even when it fails a loop check (a warning names the check); also lets the "
              "output replace an input file.")


def _parse_weights(text: str | None, n: int) -> list[float] | None:
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise MocycleError(f"--weights must be {n} comma-separated numbers >= 0 (e.g. 0.7,0.3); got {text!r}") \
            from None
    if len(values) != n:
        raise MocycleError(f"--weights needs {n} numbers, one per take; got {len(values)} in {text!r}")
    return values


def _read_all(paths: list[Path], fps: float) -> list:
    return [read(p, fps=fps) for p in paths]


@app.command()
@friendly
def blend(
    paths: Annotated[list[Path], typer.Argument(help="Two or more .bvh (or .amc) takes on one skeleton.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The blended loop as a .bvh file.")],
    weights: Annotated[str | None, typer.Option(
        help="One weight >= 0 per take, comma-separated (normalised to sum 1); default equal.")] = None,
    root: Annotated[str, typer.Option(help="inplace (on the spot) or motion (moves on by the blended stride).")]
    = "inplace",
    cycles: Annotated[int, typer.Option(help="Repeat the loop this many times in the output.")] = 1,
    method: Annotated[str, typer.Option(help=METHOD_HELP)] = "harmonic",
    model: Annotated[str, typer.Option(help=MODEL_HELP)] = "M1",
    harmonics: Annotated[str, typer.Option(help=HARMONICS_HELP)] = "auto",
    align: Annotated[bool, typer.Option(help="Search each take's phase offset against the first.")] = True,
    joints: JointsOption = None,
    classes: ClassesOption = "auto",
    which: WhichOption = None,
    pca: PcaOption = "auto",
    delay: DelayOption = 2,
    min_periods: MinPeriodsOption = 1.2,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    feet: Annotated[str, typer.Option(help=FEET_HELP)] = "auto",
    foot_joints: Annotated[str | None, typer.Option(help=FOOT_JOINTS_HELP)] = None,
):
    """Blend the cycles of several takes into one new loop (paper 001 §4.5: a convex combination).

    Each take's cycle is extracted, brought to the first one's phase, resampled to the weighted period and
    averaged with the weights in rotation space; root sway and travel per cycle are blended likewise.
    Exit code 0 on success, 3 when a take holds no periodic motion or its cycle fails a loop check (see
    mocycle loop), 1 for bad input.
    """
    from ..cycle.blend import blend_cycles, check_weights, cycle_seam

    t0 = time.perf_counter()
    if len(paths) < 2:
        raise MocycleError(f"blend needs at least two takes; got {len(paths)}")
    check_output(output, paths, force, ".bvh")
    if cycles < 1:
        raise MocycleError(f"--cycles must be a positive integer; got {cycles}")
    check_feet_mode(feet)
    w = _parse_weights(weights, len(paths))
    if w is not None:
        check_weights(w, len(paths))  # refuse bad weights before the (slower) extraction
    options = phase_options(joints, classes, pca, delay, min_periods)
    motions = _read_all(paths, fps)
    result = blend_cycles(motions, w, align=align, labels=[str(p) for p in paths], method=method, model=model,
                          n_harmonics=count_option(harmonics, "--harmonics", {"auto": "auto"}), which=which,
                          force=force, **options)
    cleaned, feet_facts, _ = clean_feet(result.cycle, feet, root, foot_joints)
    result = dc_replace(result, cycle=cleaned)
    write(result.repeat(cycles, root=root), output)
    seconds = time.perf_counter() - t0
    facts = {
        "files": [str(p) for p in paths],
        "output": str(output),
        **result.to_dict(),
        "frames_out": result.n_frames * cycles,
        "root": root,
        "cycles": cycles,
        "seam": result.seam(),
        "input_seams": [cycle_seam(c) for c in result.inputs],
        "feet": feet_facts,
        "seconds": seconds,
    }
    if as_json:
        print(json_text(facts))
        return
    out.print(f"[bold]blend[/] of {len(paths)} takes, weights "
              + ", ".join(f"{p.name} {x:.3g}" for p, x in zip(paths, result.weights, strict=True)))
    out.print("  periods (frames): " + ", ".join(f"{x:.2f}" for x in result.input_periods)
              + f" -> {result.period_frames:.2f} (loop of {result.n_frames} frames)")
    out.print("  phase offsets (cycles): " + ", ".join(f"{x:.3f}" for x in result.phase_offsets))
    move = facts["travel_per_cycle"]
    out.print(f"  travel per cycle ({move[0]:.3g}, {move[1]:.3g}, {move[2]:.3g}), "
              f"turn {facts['turn_per_cycle_deg']:.3g}°")
    seam = facts["seam"]
    out.print(f"  seam jump: pose {seam['seam_pose']:.3g}, velocity {seam['seam_velocity']:.3g} (× median step)")
    if feet_facts["mode"] == "lock":
        out.print(f"  feet locked: skate {feet_facts['skate_before']:.4g} -> {feet_facts['skate_after']:.4g} units/s")
    out.print(f"wrote {output}: {facts['frames_out']} frames ({cycles} cycle(s), root {root}) in {seconds:.2f} s")


@app.command()
@friendly
def transition(
    first: Annotated[Path, typer.Argument(help="The take to start as (.bvh or .amc).")],
    second: Annotated[Path, typer.Argument(help="The take to end as, on the same skeleton.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The transition as a .bvh file.")],
    cycles: Annotated[int, typer.Option(help="Cycles over which the weight moves from the first to the second.")]
    = 3,
    root: Annotated[str, typer.Option(help="motion (travels on) or inplace (on the spot).")] = "motion",
    method: Annotated[str, typer.Option(help=METHOD_HELP)] = "harmonic",
    model: Annotated[str, typer.Option(help=MODEL_HELP)] = "M1",
    harmonics: Annotated[str, typer.Option(help=HARMONICS_HELP)] = "auto",
    joints: JointsOption = None,
    classes: ClassesOption = "auto",
    which: WhichOption = None,
    pca: PcaOption = "auto",
    delay: DelayOption = 2,
    min_periods: MinPeriodsOption = 1.2,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    feet: Annotated[str, typer.Option(help=FEET_HELP)] = "auto",
    foot_joints: Annotated[str | None, typer.Option(help=FOOT_JOINTS_HELP)] = None,
):
    """A motion that starts as the first take's cycle and ends as the second's (paper 001 §4.5, a homotopy).

    The weight moves by a smoothstep over the cycles; period and phase stay continuous (the phase is
    integrated at the blended period). Exit code 0 on success, 3 when a take holds no periodic motion or its
    cycle fails a loop check (see mocycle loop).
    """
    from ..cycle.blend import transition as make_transition
    from ..cycle.blend import transition_smoothness

    t0 = time.perf_counter()
    check_output(output, [first, second], force, ".bvh")
    if cycles < 1:
        raise MocycleError(f"--cycles must be a positive integer; got {cycles}")
    check_feet_mode(feet)
    options = phase_options(joints, classes, pca, delay, min_periods)
    a, b = _read_all([first, second], fps)
    result = make_transition(a, b, cycles, root=root, labels=[str(first), str(second)], method=method,
                             model=model, n_harmonics=count_option(harmonics, "--harmonics", {"auto": "auto"}),
                             which=which, force=force, **options)
    written, feet_facts = lock_motion(result.motion, feet, foot_joints, root == "motion")
    write(written, output)
    seconds = time.perf_counter() - t0
    facts = {
        "files": [str(first), str(second)],
        "output": str(output),
        **result.to_dict(),
        "root": root,
        "smoothness": transition_smoothness(result),
        "feet": feet_facts,
        "seconds": seconds,
    }
    if as_json:
        print(json_text(facts))
        return
    out.print(f"[bold]transition[/] {first.name} -> {second.name} over {cycles} cycle(s)")
    out.print(f"  period {facts['period_frames_start']:.2f} -> {facts['period_frames_end']:.2f} frames; "
              f"phase offset of the second {facts['phase_offset']:.3f} cycles")
    sm = facts["smoothness"]
    out.print(f"  largest step {sm['step_local']:.3g} × its neighbours' median (inputs {sm['input_step_local']:.3g}); "
              f"largest velocity change {sm['velocity_local']:.3g} × (inputs {sm['input_velocity_local']:.3g})")
    out.print(f"wrote {output}: {facts['frames']} frames (root {root}) in {seconds:.2f} s")
