"""``mocycle compress``, ``mocycle decompress``, ``mocycle project``: keyframe compression (thesis 002)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import (
    FORCE_HELP,
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

C = tasks.compress.Options
D = tasks.decompress.Options
P = tasks.project.Options


@app.command()
@friendly
def compress(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The .mck file to write.")],
    ratio: Annotated[str, flag(C, "ratio")] = default(C, "ratio"),
    select: Annotated[str, flag(C, "select")] = default(C, "select"),
    scheme: Annotated[str, flag(C, "scheme")] = default(C, "scheme"),
    projection: Annotated[str, flag(C, "projection")] = default(C, "projection"),
    seed_projection: Annotated[str, flag(C, "seed_projection")] = default(C, "seed_projection"),
    optimize: Annotated[bool, flag(C, "optimize")] = default(C, "optimize"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    amc_fps: Annotated[float, flag(C, "amc_fps")] = default(C, "amc_fps"),
    take: Annotated[str | None, flag(C, "take")] = default(C, "take"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Compress a take to keyframes (and a 2-D trajectory for the spatial scheme); report error and size.

    The default ratio 'auto' keeps enough keys for the motion's own rhythm; an explicit ratio that leaves
    fewer than 4 keys per period gets a warning.
    """
    check_output(output, [path], force, ".mck", "--output")
    options = C(ratio=ratio, select=select, scheme=scheme, projection=projection, seed_projection=seed_projection,
                optimize=optimize, amc_fps=amc_fps, take=take)
    report = tasks.compress.run(path, options)
    print_warnings(report)
    report.result.save(output)
    r = report.facts
    facts = {k: r[k] for k in ("frames", "keyframes", "ratio", "period_frames", "keys_per_period", "keyframes_set_by",
                               "error_per_frame_per_joint", "compressed_bytes", "bvh_bytes")}
    if as_json:
        print_json({**facts, "seconds": report.seconds})
        return
    from rich.table import Table

    what = scheme if scheme != "spatial" else f"spatial/{projection}" + ("/optimised" if optimize else "")
    table = Table(title=f"{escape(path.name)} -> {escape(output.name)} ({what}, {select} keyframes)")
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


@app.command()
@friendly
def decompress(
    path: Annotated[Path, typer.Argument(help="A .mck file written by 'mocycle compress'.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The .bvh or .glb file to write.")],
    feet: Annotated[str, flag(D, "feet")] = default(D, "feet"),
    foot_joints: Annotated[str | None, flag(D, "foot_joints")] = default(D, "foot_joints"),
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    gltf_scale: Annotated[str, GLTF_SCALE] = "auto",
    gltf_up: Annotated[str, GLTF_UP] = "auto",
):
    """Rebuild a take from its keyframes; the keyframes come back exactly (unless --feet lock)."""
    check_motion_output(output, [path], force, "--output", gltf_scale, gltf_up)
    report = tasks.decompress.run(path, D(feet=feet, foot_joints=foot_joints))
    print_warnings(report)
    write_motion(report, "motion", output, gltf_scale, gltf_up)
    r = report.facts
    if as_json:
        print_json({**r, "seconds": report.seconds})
        return
    out.print(f"{escape(output)}: {r['frames']} frames rebuilt from {r['keyframes']} keyframes ({r['scheme']})")
    if r["feet"]["mode"] == "lock":
        out.print(f"  feet locked: skate {r['feet']['skate_before']:.4g} -> {r['feet']['skate_after']:.4g} units/s "
                  "(the keyframes near contacts changed with them)")


@app.command()
@friendly
def project(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    projection: Annotated[str, flag(P, "projection")] = default(P, "projection"),
    select: Annotated[str, flag(P, "select")] = default(P, "select"),
    ratio: Annotated[float, flag(P, "ratio")] = default(P, "ratio"),
    seed_projection: Annotated[str, flag(P, "seed_projection")] = default(P, "seed_projection"),
    optimize: Annotated[bool, flag(P, "optimize")] = default(P, "optimize"),
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: poses as points coloured by time, keyframes "
                                                   "marked (thesis Figure 6.2).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON (includes the 2-D points).")] = False,
    amc_fps: Annotated[float, flag(P, "amc_fps")] = default(P, "amc_fps"),
    take: Annotated[str | None, flag(P, "take")] = default(P, "take"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
):
    """Project every pose to 2-D and pick keyframes: the spatial keyframing view of a take."""
    check_output(plot, [path], force, ".png", "--plot")
    options = P(projection=projection, select=select, ratio=ratio, seed_projection=seed_projection,
                optimize=optimize, amc_fps=amc_fps, take=take)
    report = tasks.project.run(path, options)
    print_warnings(report)
    r, arrays = report.facts, report.result
    if plot is not None:
        from ..viz.keyframes import plot_projection

        name = projection if projection not in ("rbfp", "lamp") else f"{projection} ({seed_projection} seed)"
        plot_projection(arrays["points"], arrays["keyframes"], plot, title=f"{path.name}: {name}, {select} keyframes",
                        optimized=arrays["optimized"], labels=(name, f"{name}, optimised (Algorithm 12)"))
    if as_json:
        facts = {k: v for k, v in r.items() if k not in ("points", "points_optimized")}
        facts["seconds"] = report.seconds
        facts["points"] = r["points"]
        if "points_optimized" in r:
            facts["points_optimized"] = r["points_optimized"]
        print_json(facts, indent=None)
        return
    out.print(f"[bold]{escape(path)}[/]: {r['frames']} frames, {len(r['keyframes'])} keyframes ({select}), "
              f"projection {projection}")
    out.print(f"  stress (eq. 4.1): {r['stress']:.4g}" + (
        f", optimised {r['stress_optimized']:.4g}" if "stress_optimized" in r else ""))
    out.print(f"  keyframes: {', '.join(map(str, r['keyframes']))}", soft_wrap=True)
    if plot is not None:
        out.print(f"wrote {escape(plot)}", soft_wrap=True)
    out.print(timing_line(report))
