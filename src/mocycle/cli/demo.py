"""``mocycle demo``: the main job on the built-in synthetic walk."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from ..errors import MocycleError
from .common import (
    app,
    check_folder,
    escape,
    friendly,
    out,
    read,
    write,
)


@app.command()
@friendly
def demo(
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for the demo files.")] = Path("mocycle-demo"),
    seed: Annotated[int, typer.Option(help="Random seed of the synthetic take.")] = 0,
):
    """Loop the built-in synthetic walk: write the take, its cycle (BVH) and the loop plot."""
    from .. import tasks
    from ..cycle.result import Cycle
    from ..datasets import synthetic_walk
    from ..tasks.loop import METRIC_LABELS
    from ..viz import plot_loop

    check_folder(out_dir)
    t0 = time.perf_counter()
    take = synthetic_walk(seed=seed, noise_deg=1.0, speed_change=0.1)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MocycleError(f"{out_dir}: --out: cannot make the folder ({exc.strerror or exc})") from None
    source = write(take.motion, out_dir / "synthetic_walk.bvh")
    motion = read(source)
    import numpy as np

    true_period = float(np.median(take.period_frames))
    out.print(f"[bold]{escape(source)}[/]: synthetic walk, {motion.n_frames} frames at {motion.fps:.6g} fps, 1° noise, "
              f"tempo +10 % over the take; true period {true_period:.1f} frames")
    report = tasks.loop.run(motion, tasks.loop.Options(cycles=4, root="motion"))
    cycle, metrics = report.result, report.facts["metrics"]
    assert isinstance(cycle, Cycle)  # one loop asked for: the report's result is its cycle
    loop_file = write(cycle.motion("inplace"), out_dir / "walk_cycle.bvh")
    walk_file = write(report.motions["loop"], out_dir / "walk_cycle_x4.bvh")
    plot = plot_loop(motion, cycle, out_dir / "walk_cycle.png", title="mocycle demo: synthetic walk")
    out.print(f"  found {cycle.n_periods:.2f} periods of {cycle.period_frames:.2f} frames; cycle of "
              f"{cycle.n_frames} frames by harmonic regression M1, K = {cycle.harmonics}")
    for key in ("template_error", "jerk_ratio", "seam_pose", "seam_velocity", "foot_sliding",
                "input_foot_sliding"):
        label, unit = METRIC_LABELS[key]
        out.print(f"  {label:28s} {metrics[key]:8.3f} {unit}")
    out.print(f"wrote {escape(loop_file)} (one cycle, in place), {escape(walk_file)} (4 cycles walking on), "
              f"{escape(plot)}", soft_wrap=True)
    out.print(f"  time {time.perf_counter() - t0:.2f} s")
