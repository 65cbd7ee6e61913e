"""``mocycle convert``: ASF/AMC to BVH, frame ranges, resampling."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..defaults import AMC_FPS
from ..errors import MocycleError
from ..tasks.loop import parse_range
from .common import FORCE_HELP, GLTF_SCALE, GLTF_UP, app, check_motion_output, escape, friendly, out, read, write


@app.command()
@friendly
def convert(
    paths: Annotated[list[Path], typer.Argument(
        help="Input then output: IN OUT.bvh (IN: .bvh, .fbx, .glb, .gltf), or SKELETON.asf MOTION.amc OUT.bvh "
             "(or OUT.glb).")],
    fps: Annotated[float | None, typer.Option(
        help="Resample the output to this frame rate (slerp; the first and last frame's times are kept).")] = None,
    amc_fps: Annotated[float, typer.Option(
        help="Frame rate of AMC input files, which do not store it (CMU: 120).")] = AMC_FPS,
    take: Annotated[str | None, typer.Option(
        help="Which take of a glTF or FBX input to read: its name or 0-based index (mocycle info lists them); "
             "default the first that moves the skeleton.")] = None,
    frame_range: Annotated[str | None, typer.Option("--range", help="Keep frames START:STOP.")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    gltf_scale: Annotated[str, GLTF_SCALE] = "auto",
    gltf_up: Annotated[str, GLTF_UP] = "auto",
):
    """Convert ASF/AMC, FBX or glTF to BVH or glTF (.glb), or rewrite a BVH (optionally a frame range, another
    fps)."""
    if len(paths) in (2, 3):
        check_motion_output(paths[-1], paths[:-1], force, "the output", gltf_scale, gltf_up)
    if len(paths) == 2:
        motion = read(paths[0], fps=amc_fps, take=take)
    elif len(paths) == 3:
        asf, amc = paths[0], paths[1]
        if asf.suffix.lower() != ".asf" or amc.suffix.lower() != ".amc":
            raise MocycleError(f"with three paths, expected SKELETON.asf MOTION.amc OUT.bvh; got {asf} {amc}")
        motion = read(amc, asf=asf, fps=amc_fps)
    else:
        raise MocycleError("expected IN OUT.bvh or SKELETON.asf MOTION.amc OUT.bvh")
    target = paths[-1]
    start, stop = parse_range(frame_range, motion.n_frames)
    motion = motion[start:stop]
    if fps is not None:
        motion = motion.resample(fps)
    write(motion, target, gltf_scale=gltf_scale, gltf_up=gltf_up)
    out.print(f"wrote {escape(target)}: {motion.n_frames} frames, {motion.n_joints} joints, {motion.fps:.6g} fps",
              soft_wrap=True)


