"""``mocycle blend`` and ``mocycle transition``: new loops from the cycles of several takes (paper 001 §4.5)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import check_output, delivered, escape, out, print_closing, print_feet, print_json, task_command

PLOT_HELP = "Write a PNG: the most moving joint curves of the blend and of the inputs' cycles, phase-aligned."


@task_command("blend")
def blend(
    paths: Annotated[list[Path], typer.Argument(help="Two or more .bvh (or .amc) takes on one skeleton.")],
    plot: Annotated[Path | None, typer.Option(help=PLOT_HELP)] = None,
    *, options, output, as_json, force, write,
):
    """Blend the cycles of several takes into one new loop (paper 001 §4.5: a convex combination).

    Each take's cycle is extracted, brought to the first one's phase, resampled to the weighted period and
    averaged with the weights in rotation space; root sway and travel per cycle are blended likewise.
    Exit code 0 on success, 3 when a take holds no periodic motion or its cycle fails a loop check (see
    mocycle loop; --force uses it anyway), 1 for bad input, 2 for a bad option.
    """
    from ..cycle.blend import BlendedCycle

    check_output(plot, paths, force, ".png", "--plot")
    report = delivered(tasks.blend.run(paths, options))
    written = write(report)["loop"][1]
    result = report.result
    assert isinstance(result, BlendedCycle)  # what tasks.blend makes
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
    print_feet(facts["feet"])
    out.print(f"wrote {escape(output)}: {facts['frames_out']} frames ({options.cycles} cycle(s), root "
              f"{options.root})", soft_wrap=True)
    print_closing(report, plot)


@task_command("transition")
def transition(
    first: Annotated[Path, typer.Argument(help="The take to start as (.bvh, .fbx, .glb, .gltf or .amc).")],
    second: Annotated[Path, typer.Argument(help="The take to end as, on the same skeleton.")],
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: the most moving joint curves over the transition's phase, and the weight.")] = None,
    *, options, output, as_json, force, write,
):
    """A motion that starts as the first take's cycle and ends as the second's (paper 001 §4.5, a homotopy).

    The weight moves by a smoothstep over the cycles; period and phase stay continuous (the phase is
    integrated at the blended period). Exit code 0 on success, 3 when a take holds no periodic motion or its
    cycle fails a loop check (see mocycle loop), 1 for bad input, 2 for a bad option.
    """
    check_output(plot, [first, second], force, ".png", "--plot")
    report = delivered(tasks.transition.run([first, second], options), write)
    if plot is not None:
        from ..cycle.blend import Transition
        from ..viz import plot_curves

        tr = report.result
        assert isinstance(tr, Transition)  # what tasks.transition makes
        plot_curves([("transition", tr.motion, tr.phase)], plot, weights=tr.weights, xlabel="phase (cycles)",
                    title=f"transition {first.name} -> {second.name} over {options.cycles} cycle(s)")
    facts = {"files": [str(first), str(second)], "output": str(output), **report.facts, "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    out.print(f"[bold]transition[/] {escape(first.name)} -> {escape(second.name)} over {options.cycles} cycle(s)",
              soft_wrap=True)
    out.print(f"  period {facts['period_frames_start']:.2f} -> {facts['period_frames_end']:.2f} frames; "
              f"phase offset of the second {facts['phase_offset']:.3f} cycles")
    sm = facts["smoothness"]
    out.print(f"  largest step {sm['step_local']:.3g} × its neighbours' median (inputs {sm['input_step_local']:.3g}); "
              f"largest velocity change {sm['velocity_local']:.3g} × (inputs {sm['input_velocity_local']:.3g})")
    print_feet(facts["feet"])
    out.print(f"wrote {escape(output)}: {facts['frames']} frames (root {options.root})", soft_wrap=True)
    print_closing(report, plot)
