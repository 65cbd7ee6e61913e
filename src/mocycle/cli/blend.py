"""``mocycle blend`` and ``mocycle transition``: new loops from the cycles of several takes (paper 001 §4.5)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import (
    CLOSING_FRAME,
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

B = tasks.blend.Options
T = tasks.transition.Options
PLOT_HELP = "Write a PNG: the most moving joint curves of the blend and of the inputs' cycles, phase-aligned."


@app.command()
@friendly
def blend(
    paths: Annotated[list[Path], typer.Argument(help="Two or more .bvh (or .amc) takes on one skeleton.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The blended loop as a .bvh or .glb file.")],
    weights: Annotated[str | None, flag(B, "weights")] = default(B, "weights"),
    root: Annotated[str, flag(B, "root")] = default(B, "root"),
    cycles: Annotated[int, flag(B, "cycles")] = default(B, "cycles"),
    method: Annotated[str, flag(B, "method")] = default(B, "method"),
    model: Annotated[str, flag(B, "model")] = default(B, "model"),
    harmonics: Annotated[str, flag(B, "harmonics")] = default(B, "harmonics"),
    align: Annotated[bool, flag(B, "align")] = default(B, "align"),
    joints: Annotated[str | None, flag(B, "joints")] = default(B, "joints"),
    classes: Annotated[str, flag(B, "classes")] = default(B, "classes"),
    which: Annotated[int | None, flag(B, "which")] = default(B, "which"),
    pca: Annotated[str, flag(B, "pca")] = default(B, "pca"),
    delay: Annotated[int, flag(B, "delay")] = default(B, "delay"),
    min_periods: Annotated[float, flag(B, "min_periods")] = default(B, "min_periods"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help=PLOT_HELP)] = None,
    amc_fps: Annotated[float, flag(B, "amc_fps")] = default(B, "amc_fps"),
    take: Annotated[str | None, flag(B, "take")] = default(B, "take"),
    force: Annotated[bool, flag(B, "force")] = default(B, "force"),
    feet: Annotated[str, flag(B, "feet")] = default(B, "feet"),
    foot_joints: Annotated[str | None, flag(B, "foot_joints")] = default(B, "foot_joints"),
    closing_frame: Annotated[bool | None, CLOSING_FRAME] = None,
    gltf_scale: Annotated[str, GLTF_SCALE] = "auto",
    gltf_up: Annotated[str, GLTF_UP] = "auto",
):
    """Blend the cycles of several takes into one new loop (paper 001 §4.5: a convex combination).

    Each take's cycle is extracted, brought to the first one's phase, resampled to the weighted period and
    averaged with the weights in rotation space; root sway and travel per cycle are blended likewise.
    Exit code 0 on success, 3 when a take holds no periodic motion or its cycle fails a loop check (see
    mocycle loop; --force uses it anyway), 1 for bad input, 2 for a bad option.
    """
    check_motion_output(output, paths, force, "--output", gltf_scale, gltf_up)
    check_output(plot, paths, force, ".png", "--plot")
    options = B(weights=weights, root=root, cycles=cycles, method=method, model=model, harmonics=harmonics,
                align=align, joints=joints, classes=classes, which=which, pca=pca, delay=delay, min_periods=min_periods,
                amc_fps=amc_fps, take=take, force=force, feet=feet, foot_joints=foot_joints)
    report = tasks.blend.run(paths, options)
    print_warnings(report)
    written = write_motion(report, "loop", output, gltf_scale, gltf_up, closing_frame)
    result = report.result
    if plot is not None:
        import numpy as np

        from ..motion import concatenate
        from ..viz import plot_curves

        def from_phase(m, phase):  # the input cycle read from the phase the blend's frame 0 is at
            s = int(round(phase * m.n_frames)) % m.n_frames
            return concatenate([m[s:], m[:s]]) if s else m

        loops = [("blend", result.motion("inplace"))] + [
            (p.name, from_phase(c.motion("inplace"), result.start_phase + off))
            for p, c, off in zip(paths, result.inputs, result.phase_offsets, strict=True)]
        plot_curves([(label, m, np.arange(m.n_frames) / m.n_frames) for label, m in loops], plot,
                    title=f"blend of {len(paths)} takes", xlabel="phase (cycles)")
    facts = {"files": [str(p) for p in paths], "output": str(output), **report.facts, "frames_out": written.n_frames,
             "closing_frame": written.n_frames != report.motions["loop"].n_frames, "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    out.print(f"[bold]blend[/] of {len(paths)} takes, weights "
              + ", ".join(f"{escape(p.name)} {x:.3g}" for p, x in zip(paths, result.weights, strict=True)))
    out.print("  periods (frames): " + ", ".join(f"{x:.2f}" for x in result.input_periods)
              + f" -> {result.period_frames:.2f} (loop of {result.n_frames} frames)")
    out.print("  phase offsets (cycles): " + ", ".join(f"{x:.3f}" for x in result.phase_offsets))
    move = facts["travel_per_cycle"]
    out.print(f"  travel per cycle ({move[0]:.3g}, {move[1]:.3g}, {move[2]:.3g}), "
              f"turn {facts['turn_per_cycle_deg']:.3g}°")
    seam = facts["seam"]
    out.print(f"  seam jump: pose {seam['seam_pose']:.3g}, velocity {seam['seam_velocity']:.3g} (× median step)")
    _print_feet(facts["feet"])
    out.print(f"wrote {escape(output)}: {facts['frames_out']} frames ({cycles} cycle(s), root {root})", soft_wrap=True)
    if plot is not None:
        out.print(f"wrote {escape(plot)}", soft_wrap=True)
    out.print(timing_line(report))


@app.command()
@friendly
def transition(
    first: Annotated[Path, typer.Argument(help="The take to start as (.bvh, .fbx, .glb, .gltf or .amc).")],
    second: Annotated[Path, typer.Argument(help="The take to end as, on the same skeleton.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The transition as a .bvh or .glb file.")],
    cycles: Annotated[int, flag(T, "cycles")] = default(T, "cycles"),
    root: Annotated[str, flag(T, "root")] = default(T, "root"),
    method: Annotated[str, flag(T, "method")] = default(T, "method"),
    model: Annotated[str, flag(T, "model")] = default(T, "model"),
    harmonics: Annotated[str, flag(T, "harmonics")] = default(T, "harmonics"),
    joints: Annotated[str | None, flag(T, "joints")] = default(T, "joints"),
    classes: Annotated[str, flag(T, "classes")] = default(T, "classes"),
    which: Annotated[int | None, flag(T, "which")] = default(T, "which"),
    pca: Annotated[str, flag(T, "pca")] = default(T, "pca"),
    delay: Annotated[int, flag(T, "delay")] = default(T, "delay"),
    min_periods: Annotated[float, flag(T, "min_periods")] = default(T, "min_periods"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: the most moving joint curves over the transition's phase, and the weight.")] = None,
    amc_fps: Annotated[float, flag(T, "amc_fps")] = default(T, "amc_fps"),
    take: Annotated[str | None, flag(T, "take")] = default(T, "take"),
    force: Annotated[bool, flag(T, "force")] = default(T, "force"),
    feet: Annotated[str, flag(T, "feet")] = default(T, "feet"),
    foot_joints: Annotated[str | None, flag(T, "foot_joints")] = default(T, "foot_joints"),
    gltf_scale: Annotated[str, GLTF_SCALE] = "auto",
    gltf_up: Annotated[str, GLTF_UP] = "auto",
):
    """A motion that starts as the first take's cycle and ends as the second's (paper 001 §4.5, a homotopy).

    The weight moves by a smoothstep over the cycles; period and phase stay continuous (the phase is
    integrated at the blended period). Exit code 0 on success, 3 when a take holds no periodic motion or its
    cycle fails a loop check (see mocycle loop), 1 for bad input, 2 for a bad option.
    """
    check_motion_output(output, [first, second], force, "--output", gltf_scale, gltf_up)
    check_output(plot, [first, second], force, ".png", "--plot")
    options = T(cycles=cycles, root=root, method=method, model=model, harmonics=harmonics, joints=joints,
                classes=classes, which=which, pca=pca, delay=delay, min_periods=min_periods, amc_fps=amc_fps, take=take,
                force=force, feet=feet, foot_joints=foot_joints)
    report = tasks.transition.run([first, second], options)
    print_warnings(report)
    write_motion(report, "transition", output, gltf_scale, gltf_up)
    if plot is not None:
        from ..viz import plot_curves

        tr = report.result
        plot_curves([("transition", tr.motion, tr.phase)], plot, weights=tr.weights, xlabel="phase (cycles)",
                    title=f"transition {first.name} -> {second.name} over {cycles} cycle(s)")
    facts = {"files": [str(first), str(second)], "output": str(output), **report.facts, "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    out.print(f"[bold]transition[/] {escape(first.name)} -> {escape(second.name)} over {cycles} cycle(s)",
              soft_wrap=True)
    out.print(f"  period {facts['period_frames_start']:.2f} -> {facts['period_frames_end']:.2f} frames; "
              f"phase offset of the second {facts['phase_offset']:.3f} cycles")
    sm = facts["smoothness"]
    out.print(f"  largest step {sm['step_local']:.3g} × its neighbours' median (inputs {sm['input_step_local']:.3g}); "
              f"largest velocity change {sm['velocity_local']:.3g} × (inputs {sm['input_velocity_local']:.3g})")
    _print_feet(facts["feet"])
    out.print(f"wrote {escape(output)}: {facts['frames']} frames (root {root})", soft_wrap=True)
    if plot is not None:
        out.print(f"wrote {escape(plot)}", soft_wrap=True)
    out.print(timing_line(report))


def _print_feet(feet: dict) -> None:
    if feet["mode"] == "lock":
        out.print(f"  feet locked: skate {feet['skate_before']:.4g} -> {feet['skate_after']:.4g} units/s")
