"""The ``mocycle`` command: one sub-command per user task.

Thin by design: each command parses options, calls the library and prints.
Bad input ends with one ``error:`` line naming the file, the line and what
was expected, and exit code 1; usage errors exit with 2 (typer's convention).
"""

from __future__ import annotations

import json
import sys
import time
import warnings
from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from . import __version__
from .errors import MocycleError
from .io import read, write
from .io.bvh import motion_channels
from .motion import Motion

app = typer.Typer(
    name="mocycle",
    help="Turn raw motion capture into reusable animation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
out = Console(highlight=False)
err = Console(stderr=True, highlight=False)

EXIT_ERROR = 1
EXIT_NOT_FOUND = 3  # the input is fine but holds no periodic motion


def _friendly(func: Callable) -> Callable:
    """Run a command: MocycleError -> one 'error:' line and exit 1; warnings -> 'warning:' lines."""

    @wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = func(*args, **kwargs)
            except MocycleError as exc:
                _print_warnings(caught)
                err.print(f"[bold red]error:[/] {exc}", markup=True, soft_wrap=True)
                raise typer.Exit(EXIT_ERROR) from None
        _print_warnings(caught)
        return result

    return wrapper


def _print_warnings(caught) -> None:
    for w in caught:
        if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
            continue
        err.print(f"[yellow]warning:[/] {w.message}", markup=True, soft_wrap=True)


def _version(value: bool):
    if value:
        out.print(f"mocycle {__version__}")
        raise typer.Exit()


@app.callback()
def main_options(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
):
    """mocycle: periodic motion, seamless cycles, swings and keyframes from mocap files."""


# --------------------------------------------------------------------- info
def motion_info(motion: Motion) -> dict:
    """The facts ``mocycle info`` prints, as a JSON-ready dict."""
    skel = motion.skeleton
    travel = motion.travel_joint
    root = motion.world_positions()[:, travel]
    steps = np.linalg.norm(np.diff(root, axis=0), axis=1) if motion.n_frames > 1 else np.zeros(0)
    values = motion_channels(motion)
    ranges: dict[str, dict[str, float]] = {}
    spread: dict[str, float] = {}
    col = 0
    for j, name in enumerate(skel.names):
        per = {}
        for c in skel.channels[j]:
            if c.endswith("rotation"):
                per[c] = float(np.ptp(values[:, col]))
            col += 1
        if per:
            ranges[name] = per
            r = motion.rotation(j)
            spread[name] = float(np.degrees((r.mean().inv() * r).magnitude().max()))
    return {
        "frames": motion.n_frames,
        "frame_time": motion.frame_time,
        "fps": motion.fps,
        "duration_s": motion.duration,
        "joints": skel.n_joints,
        "channels": skel.n_channels,
        "end_sites": len(skel.end_sites),
        "travel_joint": skel.names[travel],
        "root_start": root[0].tolist(),
        "root_end": root[-1].tolist(),
        "root_displacement": float(np.linalg.norm(root[-1] - root[0])),
        "root_path_length": float(steps.sum()),
        "rotation_range_deg": ranges,
        "rotation_spread_deg": spread,
    }


@app.command()
@_friendly
def info(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON instead of tables.")] = False,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
):
    """Frames, frame time, fps, duration, joints, channels, root travel and rotation ranges."""
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    facts = motion_info(motion)
    facts["file"] = str(path)
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        print(json.dumps(facts, indent=2))
        return
    _print_info(facts)


def _print_info(facts: dict) -> None:
    out.print(f"[bold]{facts['file']}[/]")
    out.print(
        f"  {facts['frames']} frames × {facts['frame_time']:.6g} s = {facts['duration_s']:.3f} s "
        f"({facts['fps']:.6g} fps)\n"
        f"  {facts['joints']} joints, {facts['channels']} channels, {facts['end_sites']} end sites\n"
        f"  travel of {facts['travel_joint']}: {facts['root_displacement']:.4g} net, "
        f"{facts['root_path_length']:.4g} along the path (file units)"
    )
    ranges, spread = facts["rotation_range_deg"], facts["rotation_spread_deg"]
    order = sorted(spread, key=lambda n: -spread[n])
    shown = order if len(order) <= 40 else order[:20]
    table = Table(title="rotation per joint (degrees)")
    table.add_column("joint")
    table.add_column("max angle from mean pose", justify="right")
    table.add_column("channel ranges (max - min; large near gimbal lock)")
    for name in shown:
        table.add_row(name, f"{spread[name]:.1f}", "  ".join(f"{c[0]} {v:6.1f}" for c, v in ranges[name].items()))
    out.print(table)
    if len(shown) < len(order):
        out.print(f"  ({len(order) - len(shown)} more joints; --json lists all)")


# ------------------------------------------------------------------ convert
def _parse_range(text: str | None, n_frames: int) -> tuple[int, int]:
    if not text:
        return 0, n_frames
    try:
        a, _, b = text.partition(":")
        start = int(a) if a.strip() else 0
        stop = int(b) if b.strip() else n_frames
    except ValueError:
        raise MocycleError(f"--range must look like START:STOP (frame numbers); got {text!r}") from None
    if start < 0:
        start += n_frames
    if stop < 0:
        stop += n_frames
    if not 0 <= start < stop <= n_frames:
        raise MocycleError(f"--range {text} is outside the take's {n_frames} frames")
    return start, stop


@app.command()
@_friendly
def convert(
    paths: Annotated[list[Path], typer.Argument(
        help="Input then output: IN.bvh OUT.bvh, or SKELETON.asf MOTION.amc OUT.bvh.")],
    fps: Annotated[float | None, typer.Option(help="Resample to this frame rate (slerp).")] = None,
    amc_fps: Annotated[float, typer.Option(help="Frame rate of the AMC input (CMU: 120).")] = 120.0,
    frame_range: Annotated[str | None, typer.Option("--range", help="Keep frames START:STOP.")] = None,
):
    """Convert ASF/AMC to BVH, or rewrite a BVH (optionally a frame range, another fps)."""
    if len(paths) == 2:
        motion = read(paths[0], fps=amc_fps)
    elif len(paths) == 3:
        asf, amc = paths[0], paths[1]
        if asf.suffix.lower() != ".asf" or amc.suffix.lower() != ".amc":
            raise MocycleError(f"with three paths, expected SKELETON.asf MOTION.amc OUT.bvh; got {asf} {amc}")
        motion = read(amc, asf=asf, fps=amc_fps)
    else:
        raise MocycleError("expected IN OUT.bvh or SKELETON.asf MOTION.amc OUT.bvh")
    target = paths[-1]
    if target.suffix.lower() != ".bvh":
        raise MocycleError(f"{target}: the output must be a .bvh file")
    start, stop = _parse_range(frame_range, motion.n_frames)
    motion = motion[start:stop]
    if fps is not None:
        motion = motion.resample(fps)
    write(motion, target)
    out.print(f"wrote {target}: {motion.n_frames} frames, {motion.n_joints} joints, {motion.fps:.6g} fps")


# -------------------------------------------------------------------- phase
def _count_option(text: str, option: str, words: dict[str, object]) -> object:
    """A positive integer option that also takes a few words (e.g. 'auto')."""
    if text in words:
        return words[text]
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise MocycleError(f"{option} must be {' or '.join(repr(w) for w in words)} or a positive integer; "
                           f"got {text!r}")
    return n


@app.command()
@_friendly
def phase(
    path: Annotated[Path, typer.Argument(help="A .bvh file, or an .amc file (its .asf beside it).")],
    classes: Annotated[str, typer.Option(help="Number of periodic motions: 'auto' or N.")] = "auto",
    joints: Annotated[str | None, typer.Option(
        help="Joints to use: names, glob patterns or groups (legs, arms, spine), comma-separated.")] = None,
    pca: Annotated[str, typer.Option(help="PCA dimensions before the cohomology: 'auto' (8), N or 'none'.")] = "auto",
    delay: Annotated[int, typer.Option(help="Delay embedding factor m (KTH thesis eq. 3.26; it used 2).")] = 2,
    landmarks: Annotated[int, typer.Option(help="Landmarks for the Rips filtration.")] = 120,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write a PNG: diagram, phase per frame, PCA by phase.")] = None,
    fps: Annotated[float, typer.Option(help="Frame rate of AMC files (they do not store it).")] = 120.0,
):
    """Find periodic motions and the phase of every frame (persistent cohomology).

    Exit code 0 when at least one periodic motion is found, 3 when none is
    (the reason is printed), 1 for bad input.
    """
    from .phase import find_phase

    if delay < 0:
        raise MocycleError(f"--delay must be >= 0; got {delay}")
    t0 = time.perf_counter()
    motion = read(path, fps=fps)
    result = find_phase(motion, classes=_count_option(classes, "--classes", {"auto": "auto"}), joints=joints,
                        pca=_count_option(pca, "--pca", {"auto": "auto", "none": None, "0": None}),
                        delay=delay, n_landmarks=landmarks)
    if plot is not None:
        from .viz import plot_phase

        plot_phase(result, plot, title=path.name)
    facts = result.to_dict()
    facts["seconds"] = time.perf_counter() - t0
    if as_json:
        print(json.dumps(facts, indent=2))
    else:
        _print_phase(path, facts)
    if not result.classes:
        err.print(f"no periodic motion found: {result.reason}", soft_wrap=True)
        raise typer.Exit(EXIT_NOT_FOUND)


def _print_phase(path: Path, facts: dict) -> None:
    out.print(f"[bold]{path}[/]: {facts['frames']} frames at {facts['fps']:.6g} fps")
    table = Table(title="periodic motions (H1 classes)")
    for col in ("class", "bar [birth, death)", "period frames", "period s", "periods", "excitation frames"):
        table.add_column(col, justify="right" if col != "excitation frames" else "left")
    for k, c in enumerate(facts["classes"]):
        table.add_row(str(k), f"[{c['birth']:.3g}, {c['death']:.3g})", f"{c['period_frames']:.2f}",
                      f"{c['period_s']:.3f}", f"{c['n_periods']:.2f}",
                      ", ".join(f"{s}-{e}" for s, e in c["excitation"]))
    if facts["classes"]:
        out.print(table)
    acf = facts["autocorrelation_period_frames"]
    out.print(f"  autocorrelation period (cross-check): {'none' if acf is None else f'{acf:.2f} frames'}")
    out.print(f"  why: {facts['reason']}", soft_wrap=True)
    out.print(f"  {facts['seconds']:.3f} s")


# --------------------------------------------------------------------- demo
@app.command()
@_friendly
def demo(
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for the demo files.")] = Path("mocycle-demo"),
    seed: Annotated[int, typer.Option(help="Random seed of the synthetic take.")] = 0,
):
    """Make the built-in synthetic walk, write it as BVH and print its facts."""
    from .datasets import synthetic_walk

    t0 = time.perf_counter()
    take = synthetic_walk(seed=seed, noise_deg=0.5)
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / "synthetic_walk.bvh"
    write(take.motion, target)
    back = read(target)
    facts = motion_info(back)
    facts["file"] = str(target)
    _print_info(facts)
    n_cycles = float(take.unwrapped_phase[-1] - take.unwrapped_phase[0])
    out.print(
        f"synthetic walk: period {float(np.median(take.period_frames)):.1f} frames, "
        f"{n_cycles:.2f} cycles; written and read back in {time.perf_counter() - t0:.2f} s"
    )


def main() -> None:  # the console script
    try:
        app()
    except KeyboardInterrupt:  # pragma: no cover
        err.print("interrupted")
        sys.exit(130)


if __name__ == "__main__":  # pragma: no cover
    main()
