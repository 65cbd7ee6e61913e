"""``mocycle loop``: one seamless typical cycle of a take, written as BVH."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion
from ..tasks.loop import METRIC_LABELS
from ..tasks.report import Report
from .common import (
    as_flags,
    check_output,
    escape,
    out,
    print_closing,
    print_feet,
    print_json,
    print_warnings,
    task_command,
)


@task_command("loop")
def loop(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: PCA of input and cycle, phase, joint curves (with --part all: OUT.part<k>-<kind>.png).")]
    = None,
    feet_plot: Annotated[Path | None, typer.Option(
        help="Write a PNG of the contacts: each ankle and toe's height and speed over two cycles, before (dashed) "
             "and after locking (with --part all: OUT.part<k>-<kind>.png).")] = None,
    *, options, as_json, force, write,
):
    """Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH or glTF.

    A .glb output holds the clip OUT_loop (Godot loops clips so named) with the closing frame, and the loop's
    facts in its extras (docs/formats.md).

    Exit code 0 on success, 3 when the take holds no periodic motion or its cycle fails a loop check
    (the reason is printed; --force writes it anyway), 1 for bad input, 2 for a bad option.
    """
    check_output(plot, [path], force, ".png", "--plot")
    check_output(feet_plot, [path], force, ".png", "--feet-plot")
    plots = plot is not None or feet_plot is not None
    try:  # without plots each loop is written as soon as it is made, and let go (a long session's hundreds)
        report = tasks.loop.run(path, options, deliver=None if plots else write)
    except (NoPeriodicMotion, LoopRefused) as exc:
        if as_json and exc.facts is not None:  # the same shape, status and reason: exit 3
            print_json({"file": str(path), **exc.facts})
        raise
    everything = options.which == "all"
    loops = report.facts["loops"]
    roles = [f["role"] for f in loops]
    if feet_plot is not None and any(_extra(report, r)["contacts"] is None for r in roles):
        # refused before any file is written
        raise MocycleError("--feet-plot needs locked feet (--feet lock, or auto with --root motion)")
    print_warnings(report)
    if plots:  # every cycle was made and checked before writing; one file per loop (OUT.part<k>-...)
        files = {role: (str(target), written.n_frames, report.motions[role].n_frames != written.n_frames)
                 for role, (target, written) in write(report).items()}
        if everything:
            assert isinstance(report.result, list)  # --part all: the cycle of each loop
            cycles_made: list[object] = report.result
        else:
            cycles_made = [report.result]
    else:
        files = {role: w for r in roles for role, w in _extra(report, r)["written"].items()}
        cycles_made = [None] * len(loops)
    shown = []
    for facts, cycle in zip(loops, cycles_made, strict=True):
        role = facts["role"]
        tag = tasks.loop.output_tag(facts)
        target, frames_out, closing = files[role]
        images = []
        if feet_plot is not None:
            images.append(feet_plot.with_suffix(f".{tag}.png") if tag else feet_plot)
            _plot_feet(_extra(report, role)["fitted"], cycle, _extra(report, role)["contacts"], images[-1],
                       f"{path.name}: feet locked")
        if plot is not None:
            from ..viz import plot_loop

            images.append(plot.with_suffix(f".{tag}.png") if tag else plot)
            plot_loop(report.motions["input"], cycle, images[-1],
                      title=f"{path.name}: {options.method}"
                      + (f" {options.model}" if options.method == "harmonic" else ""))
        facts.update(output=target, frames_out=frames_out, closing_frame=closing)
        shown.append(({"file": str(path), **facts, "seconds": report.seconds,
                       "metrics_seconds": report.timings_s["metrics"]}, images))
    if as_json:
        top = {k: v for k, v in report.facts.items() if k not in shown[0][0]}
        print_json({**shown[0][0], **top, "loops": [f for f, _ in shown], "timings_s": report.timings_s})
        return
    _print_parts(path, report.facts)
    for facts, images in shown:
        _print_loop(facts)
        for image in images:
            out.print(f"wrote {escape(image)}", soft_wrap=True)
    print_closing(report)


def _extra(report: Report, role: str) -> dict:
    """What tasks.loop keeps beside a loop (its fitted cycle and contacts, or what was written of it)."""
    extra = report.extras[role]
    assert isinstance(extra, dict)
    return extra


def _print_parts(path: Path, facts: Mapping) -> None:
    """The take's parts, one line each, and which one was looped and why."""
    parts = facts["parts"]
    if len(parts) > 1:
        out.print(f"[bold]{escape(path)}[/]: {len(parts)} parts")
        for k, p in enumerate(parts):
            a, b = p["frames"]
            what = (f"{p['n_periods']:.1f} cycles of {p['period_frames']:.1f} frames"
                    if p["loop"] and p["period_frames"] else escape(p["reason"]))
            out.print(f"  part {k}: frames {a}-{b}, {p['kind']}: {what}", soft_wrap=True)
    out.print(escape(as_flags(facts["reason"], "loop")), soft_wrap=True)
    for d in facts["not_looped"]:
        if str(d["reason"]).startswith("refused"):
            out.print(f"  part {d['part']} ({d['kind']}) not looped: {escape(d['reason'])}", soft_wrap=True)


def _plot_feet(fitted, cycle, contacts, image: Path, title: str) -> None:
    """The contacts plot over two cycles of the locked loop, the fitted one dashed."""
    import numpy as np

    from ..contacts import Contacts
    from ..viz import plot_contacts

    twice = Contacts(contacts.feet, contacts.joints, contacts.foot_of, np.tile(contacts.mask, (2, 1)), contacts.up,
                     contacts.body, contacts.frame_time)
    plot_contacts(cycle.repeat(2, root="motion"), twice, image, title=title, before=fitted.repeat(2, root="motion"))


def _print_loop(facts: dict) -> None:
    from rich.table import Table

    kind = facts["method"] + (f" {facts['model']}, K = {facts['harmonics']}" if facts["method"] == "harmonic" else "")
    where = f"part {facts['part']} ({facts['kind']}, frames {facts['frames'][0]}-{facts['frames'][1]})"
    out.print(f"[bold]{escape(facts['file'])}[/]: {facts['frames_in']} frames at {facts['fps']:.6g} fps")
    out.print(f"  {where}: {facts['n_periods']:.2f} periods of {facts['period_frames']:.2f} frames "
              f"(time axis: {facts['time_axis']}, {facts['excited_regions']} excited region(s): "
              + ", ".join(f"{s}-{e}" for s, e in facts["excitation"])
              + f"; joints used: {escape(facts['joints_used'])})", soft_wrap=True)
    out.print(f"  period: {escape(facts['period_reason'])}", soft_wrap=True)
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
        spans = "; ".join(f"{escape(side)} {' '.join(f'{a}-{b}' for a, b in v['contacts'])}" for side, v in
                          f["contacts"].items())
        print_feet(f, note=f" (contacts, cycle frames: {spans})", tail=f" in {f['seconds']:.2f} s")
    out.print(f"wrote {escape(facts['output'])}: {facts['frames_out']} frames ({facts['cycles']} cycle(s), root "
              f"{facts['root']})", soft_wrap=True)
