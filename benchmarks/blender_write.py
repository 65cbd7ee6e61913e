"""Blender conversion timings: writing a 100-joint, 600-frame Motion as an action, and reading it back.

    .venv-bpy50/bin/python benchmarks/blender_write.py [--repeat N] [--zip dist/mocycle-...-linux_x64.zip]

Run with a bpy venv (``make test-blender`` makes them). Installs the extension zip (built here for linux-x64
when ``--zip`` is not given) into a temporary Blender user folder, imports a generated 100-joint take (a
binary tree of bones, smooth random Euler curves, 60 fps) with ``bpy.ops.import_anim.bvh``, then times
``rig.write_action`` (every bone's curves, keys in bulk) and ``rig.to_motion`` (median of N runs after a
warm-up). The goal: well under a second to write.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
GOAL_S = 1.0


def take(n_joints=100, n_frames=600, seed=0):
    import numpy as np

    from mocycle import Motion, Skeleton
    from mocycle.rotations import euler_to_quats

    rng = np.random.default_rng(seed)
    parents = np.array([-1] + [(j - 1) // 2 for j in range(1, n_joints)])
    offsets = rng.normal(scale=5.0, size=(n_joints, 3))
    chans = [("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")]
    chans += [("Zrotation", "Yrotation", "Xrotation")] * (n_joints - 1)
    sk = Skeleton(tuple(f"bone{j}" for j in range(n_joints)), parents, offsets, tuple(chans))
    t = np.arange(n_frames)[:, None, None] / 60.0
    angles = 0.5 * np.sin(2 * np.pi * rng.uniform(0.5, 2, (1, n_joints, 3)) * t + rng.uniform(0, 6, (1, n_joints, 3)))
    root = np.stack([np.zeros(n_frames), np.full(n_frames, 90.0), np.linspace(0, 600, n_frames)], axis=1)
    return Motion(sk, euler_to_quats(angles, "ZYX"), None, 1 / 60, root_positions=root)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--zip", help="extension zip (default: build the linux-x64 one)")
    args = ap.parse_args(argv)
    os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="mocycle-bench-")
    import bpy

    zip_path = args.zip
    if not zip_path:
        out = Path(tempfile.mkdtemp())
        subprocess.run([sys.executable, str(REPO / "blender" / "build_extension.py"), "--platform", "linux-x64",
                        "--out", str(out)], check=True, capture_output=True)
        zip_path = str(next(out.glob("*.zip")))
    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    import mocycle

    rig = sys.modules["bl_ext.user_default.mocycle"].rig
    motion = take()
    path = Path(tempfile.mkdtemp()) / "tree.bvh"
    mocycle.write(motion, path)
    bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=True, update_scene_duration=True)
    arm = bpy.context.active_object
    source = rig.to_motion(arm)
    write, read = [], []
    for k in range(args.repeat + 1):
        t = time.perf_counter()
        action = rig.write_action(arm, source, f"bench{k}")
        t1 = time.perf_counter()
        rig.to_motion(arm, action, (1, source.n_frames))
        t2 = time.perf_counter()
        if k:
            write.append(t1 - t)
            read.append(t2 - t1)
    w, r = statistics.median(write), statistics.median(read)
    print(f"bpy {bpy.app.version_string}: {source.n_joints} joints x {source.n_frames} frames "
          f"({source.n_joints * 3 + 3} curves): write_action {w * 1e3:.0f} ms, to_motion {r * 1e3:.0f} ms "
          f"(median of {args.repeat}); goal: write well under {GOAL_S:.0f} s: {'met' if w < GOAL_S / 3 else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
