"""Animated FBX and glTF files as game and DCC tools write them, read by mocycle and by Blender side by side.

    python benchmarks/engine_files.py [FILE ...] [--blender .venv-bpy52/bin/python] [--data ../shared/data]

For each file (default: ``--data``'s ``engine/`` files) and each take: mocycle's joints, frames, frame rate,
vertical (declared by the file or detected) and the glTF writer's unit, and which take ``mocycle.read``
takes by default; with ``--blender`` (a Python with the ``bpy`` module: ``make .venv-bpy52/.installed``) the
same file imported by Blender's own FBX or glTF importer into an empty scene: its bones, its scene frame
rate (the FBX importer sets the file's; the glTF importer keeps the scene's, set here to mocycle's rate
first, and turns key times into frames), and each action's frame range.  ``--blender`` also makes files
with Blender's exporters from the synthetic walk: FBX and GLB at 24 and at 60 fps, and an FBX whose first
take holds a still pose (as six of ten Mixamo files begin with an empty "Take 001").  ``docs/formats.md``
has the figures.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

EXPORT = r"""
import sys, bpy
from pathlib import Path
out = Path(sys.argv[1])
for bvh in sys.argv[2:]:
    bvh = Path(bvh)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_anim.bvh(filepath=str(bvh), global_scale=0.01, update_scene_fps=True, update_scene_duration=True)
    arm = bpy.context.active_object
    if bvh.stem == "two_takes":
        walk = arm.animation_data.action
        walk.name = "walk"
        still = walk.copy()
        still.name = "Take 001"
        bags = [b for layer in getattr(still, "layers", []) for s in layer.strips for b in s.channelbags]
        for fc in [fc for b in bags for fc in b.fcurves] or list(getattr(still, "fcurves", [])):
            hold = fc.keyframe_points[0].co.y
            for key in fc.keyframe_points:
                key.co.y = key.handle_left.y = key.handle_right.y = hold
        still.use_fake_user = True
        bpy.ops.export_scene.fbx(filepath=str(out / "blender_two_takes.fbx"), bake_anim=True,
                                 bake_anim_use_all_actions=True)
        continue
    bpy.ops.export_scene.fbx(filepath=str(out / f"blender_{bvh.stem}.fbx"), bake_anim=True)
    bpy.ops.export_scene.gltf(filepath=str(out / f"blender_{bvh.stem}.glb"), export_format="GLB",
                              export_animations=True)
"""

IMPORT = r"""
import json, sys, bpy
rows = []
for path, fps in json.loads(sys.argv[1]):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = (round(fps), round(fps) / fps) if fps else (30, 1.0)
    if path.lower().endswith(".fbx"):
        bpy.ops.import_scene.fbx(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    rows.append({"file": path, "fps": sc.render.fps / sc.render.fps_base,
                 "bones": max((len(a.data.bones) for a in arms), default=0),
                 "actions": {a.name: list(a.frame_range) for a in bpy.data.actions}})
print("ROWS" + json.dumps(rows))
"""


def blender_files(python: str, folder: Path) -> list[Path]:
    """FBX and GLB files Blender exports from the synthetic walk (24 and 60 fps; two takes, a still one first)."""
    import mocycle
    from mocycle.datasets import synthetic_walk

    bvhs = []
    for name, fps, frames in (("walk24", 24, 63), ("walk60", 60, 264), ("two_takes", 30, 90)):
        walk = synthetic_walk(n_frames=frames, fps=fps, period_s=1.0, noise_deg=0.5, seed=3).motion
        bvhs.append(str(mocycle.write(walk, folder / f"{name}.bvh")))
    done = subprocess.run([python, "-c", EXPORT, str(folder), *bvhs], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"error: Blender's export failed:\n{done.stderr[-2000:]}")
    return sorted(folder.glob("blender_*.fbx")) + sorted(folder.glob("blender_*.glb"))


def mocycle_rows(path: Path) -> list[dict]:
    """One row per take: what mocycle reads."""
    import mocycle
    from mocycle.axes import vertical_axis
    from mocycle.errors import DefaultTake
    from mocycle.io import takes
    from mocycle.io.gltf import gltf_frame

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DefaultTake)
        default = mocycle.read(path).cache("take")
    rows = []
    for take in takes(path):
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            m = mocycle.read(path, take=take)
            frame = gltf_frame(m)
        up = vertical_axis(m)
        axis = ("-" if up.min() < 0 else "+") + "xyz"[int(abs(up).argmax())]
        rows.append({"take": take, "default": take == default, "joints": m.n_joints,
                     "ends": len(m.skeleton.end_sites), "frames": m.n_frames,
                     "fps": round(m.fps, 4), "up": axis + (" (file)" if m.skeleton.up is not None else " (body)"),
                     "glb_unit": frame.unit, "warnings": [str(w.message).split(": ", 1)[-1] for w in said]})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", type=Path)
    ap.add_argument("--blender", help="a Python with bpy: Blender's import beside mocycle's, and Blender-made files")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    args = ap.parse_args(argv)
    files = list(args.files) or sorted((args.data / "engine").glob("*.*"))
    folder = Path(tempfile.mkdtemp(prefix="engine-files-"))
    if args.blender:
        files += blender_files(args.blender, folder)
    if not files:
        sys.exit(f"error: no files given and none in {args.data / 'engine'}")
    report = {str(p): {"mocycle": mocycle_rows(p)} for p in files}
    if args.blender:
        asks = [(str(p), rows["mocycle"][0]["fps"]) for p, rows in zip(files, report.values(), strict=True)]
        done = subprocess.run([args.blender, "-c", IMPORT, json.dumps(asks)], capture_output=True, text=True)
        line = next((ln for ln in done.stdout.splitlines() if ln.startswith("ROWS")), None)
        if done.returncode != 0 or line is None:
            sys.exit(f"error: Blender's import failed:\n{done.stderr[-2000:]}")
        for row in json.loads(line[4:]):
            report[row.pop("file")]["blender"] = row
    for path, rows in report.items():
        print(f"\n{Path(path).name}")
        blender = rows.get("blender")
        if blender:
            print(f"  Blender: {blender['bones']} bones (joints and ends), scene at {blender['fps']:g} fps")
        for r in rows["mocycle"]:
            mark = "*" if r["default"] else " "
            line = (f"  {mark} {r['take'][:22]:22s} {r['joints']:3d} joints + {r['ends']:2d} ends "
                    f"{r['frames']:4d} frames "
                    f"at {r['fps']:g} fps, up {r['up']}, glb unit {r['glb_unit']}")
            if blender:
                acts = blender["actions"]
                hit = [(n, acts[n]) for n in acts if n == r["take"]] or \
                    [(n, fr) for n, fr in acts.items() if set(r["take"].split("|")) & set(n.split("|"))]
                if hit:
                    start, end = hit[0][1]
                    line += f" | Blender: {end - start + 1:g} frames ({start:g}..{end:g})"
            print(line)
            for w in r["warnings"]:
                print(f"      warning: {w}")
    print("\n(* the take read without --take)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
