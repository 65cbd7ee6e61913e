"""``mocycle swings``, ``mocycle search``, ``mocycle edit``: joint swings (paper 003)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from .common import check_output, delivered, escape, out, print_closing, print_facts, print_json, task_command

_FACT_KEYS = ("joints", "n_swings", "segmentation_error", "per_angle_error_deg", "geodesic_error_deg",
              "compressed_bytes", "raw_float32_bytes")


@task_command("swings")
def swings(
    path: Annotated[Path, typer.Argument(
        help="A motion file (.bvh, .fbx, .glb, .gltf, .amc), or a .mosw swings file to play back.")],
    plot: Annotated[Path | None, typer.Option(
        help="Write a PNG: one row per joint, swings as numbered bars in time (the numbers edit --swing takes).")]
    = None,
    *, options, output, playback, as_json, force, write,
):
    """Segment a take into joint swings and holds; report playback error and compressed size.

    The table lists each joint's swing indices (0-based, in time order): what `mocycle edit --swing` takes.
    """
    from ..segmentation import Segmentation

    check_output(plot, [path], force, ".png", "--plot")
    report = delivered(tasks.swings.run(path, options))
    seg, r = report.result, report.facts
    assert isinstance(seg, Segmentation)  # what tasks.swings makes (or reads from a .mosw)
    written = []
    if write(report):
        written.append(f"{output} ({seg.n_swings} swings)")
    if write(report, "--playback"):
        written.append(f"{playback} (motion rebuilt from the swings)")
    if plot is not None:
        from ..viz.swings import plot_swings

        plot_swings(seg, plot, title=f"{path.name}: {seg.n_swings} swings (threshold {seg.threshold:g})")
        written.append(str(plot))
    facts = {**{k: r[k] for k in _FACT_KEYS}, "swing_indices": {row["joint"]: row["indices"] for row in r["per_joint"]},
             "seconds": report.seconds}
    if as_json:
        print_json(facts)
        return
    from rich.table import Table

    out.print(f"[bold]{escape(path)}[/]: {r['frames']} frames at {r['fps']:.6g} fps, "
              f"Acceptable Swing Error {r['threshold']:g}", soft_wrap=True)
    table = Table(title="swings per joint", caption="swing indices: 0-based in time order, what edit --swing takes")
    for col in ("joint", "swings", "indices", "mean length s", "mean angle deg", "holds"):
        table.add_column(col, justify="left" if col == "joint" else "right")
    for row in r["per_joint"]:
        table.add_row(escape(row["joint"]), str(row["swings"]), row["indices"] or "-", f"{row['mean_length_s']:.3f}",
                      f"{row['mean_angle_deg']:.1f}", str(row["holds"]))
    out.print(table)
    if r["segmentation_error"] is not None:
        out.print(f"  Segmentation Error {r['segmentation_error']:.2f} deg "
                  f"({r['per_angle_error_deg']:.3f} deg per angle, the paper's measure); "
                  f"geodesic {r['geodesic_error_deg']:.2f} deg per joint")
    out.print(f"  compressed {r['compressed_bytes']} bytes = {r['ratio_raw']:.3f} of the raw float32 "
              f"channels ({r['raw_float32_bytes']} bytes)"
              + (f", {r['ratio_bvh']:.3f} of the BVH text" if r["ratio_bvh"] else ""))
    print_closing(report, *written)


@task_command("search")
def search(
    query: Annotated[Path, typer.Argument(help="The example take (.bvh, .fbx, .glb, .gltf or .amc).")],
    folder: Annotated[Path, typer.Argument(help="Folder of takes to search.")],
    *, options, as_json,
):
    """Rank the takes of a folder by how alike their swings are to an example (query by example)."""
    report = delivered(tasks.search.run(query, folder, options))
    if as_json:
        r = report.facts
        print_json({"query": r["query"], "indexed": r["indexed"], "seconds": report.seconds, "results": r["results"]})
        return
    from rich.table import Table

    table = Table(title=f"{escape(query.name)} against {report.facts['indexed']} takes in {escape(folder)}")
    for col in ("rank", "score", "offset s", "take"):
        table.add_column(col, justify="left" if col == "take" else "right")
    for hit in report.facts["results"]:
        table.add_row(str(hit["rank"]), f"{hit['score']:.3f}", f"{hit['offset_s']:+.2f}",
                      escape(Path(hit["path"]).name))
    out.print(table)
    print_closing(report)


@task_command("edit")
def edit(
    path: Annotated[Path, typer.Argument(help="A motion file (.bvh, .fbx, .glb, .gltf or .amc).")],
    *, options, output, as_json, write,
):
    """Scale the angle or the duration of one swing of one joint and write the edited motion."""
    report = delivered(tasks.edit.run(path, options), write)
    if as_json:
        print_facts(report, output=str(output))
        return
    r, o = report.facts, options
    out.print(f"{escape(o.joint)} swing {o.swing} (frames {r['start']}-{r['end']}, {r['angle_deg']:.1f} deg): "
              f"angle x{o.angle_scale:g}, duration x{o.duration_scale:g} -> {escape(output)}", soft_wrap=True)
