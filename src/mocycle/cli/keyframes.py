"""``mocycle compress``, ``mocycle decompress``, ``mocycle project``: keyframe compression (thesis 002)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import (
    check_output,
    delivered,
    escape,
    out,
    print_closing,
    print_facts,
    print_feet,
    print_json,
    task_command,
)


@task_command("compress")
def compress(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    *, options, output, as_json, write,
):
    """Compress a take to keyframes (and a 2-D trajectory for the spatial scheme); report error and size.

    The default ratio 'auto' keeps enough keys for the motion's own rhythm; an explicit ratio that leaves
    fewer than 4 keys per period gets a warning.
    """
    report = delivered(tasks.compress.run(path, options), write)
    r = report.facts
    facts = {k: r[k] for k in ("frames", "keyframes", "ratio", "period_frames", "keys_per_period", "keyframes_set_by",
                               "error_per_frame_per_joint", "compressed_bytes", "bvh_bytes")}
    if as_json:
        print_json({**facts, "seconds": report.seconds})
        return
    from rich.table import Table

    o = options
    what = o.scheme if o.scheme != "spatial" else f"spatial/{o.projection}" + ("/optimised" if o.optimize else "")
    table = Table(title=f"{escape(path.name)} -> {escape(output.name)} ({what}, {o.select} keyframes)")
    table.add_column("")
    table.add_column("value", justify="right")
    table.add_row("frames", str(r["frames"]))
    table.add_row("keyframes", f"{r['keyframes']} ({r['keyframe_ratio']:.1%}, set by {r['keyframes_set_by']})")
    if r["period_frames"] is not None:
        table.add_row("keys per period", f"{r['keys_per_period']:.1f} (period {r['period_frames']:.1f} frames)")
    table.add_row("error per frame per joint (eq. 3.2, rad)", f"{r['error_per_frame_per_joint']:.4f}")
    table.add_row("compressed bytes", f"{r['compressed_bytes']:,}")
    table.add_row("BVH bytes", f"{r['bvh_bytes']:,}" if r["bvh_bytes"] is not None else "-")
    table.add_row("real ratio", f"{r['real_ratio']:.2%}" if r["real_ratio"] is not None else "-")
    table.add_row("formula 5.2/5.3 ratio (h = 0)", f"{r['formula_ratio']:.2%}")
    table.add_row("time (s)", f"{report.seconds:.2f}")
    out.print(table)
    out.print(f"wrote {escape(output)}", soft_wrap=True)


@task_command("decompress")
def decompress(
    path: Annotated[Path, typer.Argument(help="A .mck file written by 'mocycle compress'.")],
    *, options, output, as_json, write,
):
    """Rebuild a take from its keyframes; the keyframes come back exactly (unless --feet lock)."""
    report = delivered(tasks.decompress.run(path, options), write)
    if as_json:
        print_facts(report)
        return
    r = report.facts
    out.print(f"{escape(output)}: {r['frames']} frames rebuilt from {r['keyframes']} keyframes ({r['scheme']})")
    print_feet(r["feet"], tail=" (the keyframes near contacts changed with them)")


@task_command("project")
def project(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: poses as points coloured by time, keyframes "
                                                   "marked (thesis Figure 6.2).")] = None,
    *, options, as_json, force,
):
    """Project every pose to 2-D and pick keyframes: the spatial keyframing view of a take."""
    check_output(plot, [path], force, ".png", "--plot")
    report = delivered(tasks.project.run(path, options))
    r, arrays = report.facts, report.result
    assert isinstance(arrays, dict)  # tasks.project's points, keyframes and optimised points
    if plot is not None:
        from ..viz.keyframes import plot_projection

        o = options
        name = o.projection if o.projection not in ("rbfp", "lamp") else f"{o.projection} ({o.seed_projection} seed)"
        plot_projection(arrays["points"], arrays["keyframes"], plot, title=f"{path.name}: {name}, {o.select} keyframes",
                        optimized=arrays["optimized"], labels=(name, f"{name}, optimised (Algorithm 12)"))
    if as_json:
        facts = {k: v for k, v in r.items() if k not in ("points", "points_optimized")}
        facts["seconds"] = report.seconds
        facts["points"] = r["points"]
        if "points_optimized" in r:
            facts["points_optimized"] = r["points_optimized"]
        print_json(facts, indent=None)
        return
    out.print(f"[bold]{escape(path)}[/]: {r['frames']} frames, {len(r['keyframes'])} keyframes ({options.select}), "
              f"projection {options.projection}")
    out.print(f"  stress (eq. 4.1): {r['stress']:.4g}" + (
        f", optimised {r['stress_optimized']:.4g}" if "stress_optimized" in r else ""))
    out.print(f"  keyframes: {', '.join(map(str, r['keyframes']))}", soft_wrap=True)
    print_closing(report, plot)
