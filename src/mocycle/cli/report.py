"""``mocycle report``: one self-contained HTML page of a take and its loop (viewer, phase strip, metrics)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .. import tasks
from ..errors import NoPeriodicMotion
from ..io.atomic import atomic_write
from ..text import printable
from .common import app, check_output, default, err, escape, flag, friendly, out, print_warnings

L = tasks.loop.Options


@app.command()
@friendly
def report(
    path: Annotated[Path, typer.Argument(help="A motion file: .bvh, .fbx, .glb, .gltf, or .amc (its .asf beside it).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The .html file to write.")],
    method: Annotated[str, flag(L, "method")] = default(L, "method"),
    model: Annotated[str, flag(L, "model")] = default(L, "model"),
    root: Annotated[str, flag(L, "root")] = "motion",
    feet: Annotated[str, flag(L, "feet")] = default(L, "feet"),
    amc_fps: Annotated[float, flag(L, "amc_fps")] = default(L, "amc_fps"),
    take: Annotated[str | None, flag(L, "take")] = default(L, "take"),
    force: Annotated[bool, typer.Option("--force", help=(
        "Write the report even when the loop fails a loop check (the page names them in a red banner); "
        "it also lets the output replace an input file."))] = False,
):
    """Write one HTML file (viewer, the take beside its loop repeated with root motion, phase strip, metrics)
    that opens offline in a browser: to mail or attach to a ticket.  The loop plays in step with the take's
    phase over the whole take.

    A loop that fails its checks is refused as by mocycle loop: the reason is printed, exit code 3, no file
    written; --force writes the report anyway, with the failed checks in a banner at the top.  A take without
    periodic motion gets a page with the take and the reason (and a warning).
    """
    check_output(output, [path], force, (".html", ".htm"), "--output")
    from ..studio.report import report_pieces

    options = L(method=method, model=model, root=root, feet=feet, amc_fps=amc_fps, take=take, force=force)
    loop_report, reason = None, None
    try:
        loop_report = tasks.loop.run(path, options)  # LoopRefused (exit 3, nothing written) unless --force
        motion = loop_report.motions["input"]
        print_warnings(loop_report)
    except NoPeriodicMotion as exc:
        motion = tasks.info.run(path, tasks.info.Options(amc_fps=amc_fps, take=take)).motions["motion"]
        reason = str(exc)
        err.print(f"[yellow]warning:[/] no loop in the report: {escape(reason)}", markup=True, soft_wrap=True)
    atomic_write(output, report_pieces(printable(path.name), motion, loop_report, reason))
    out.print(f"wrote {escape(output)}", soft_wrap=True)
