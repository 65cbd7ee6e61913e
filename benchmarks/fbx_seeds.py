"""FBX seed files for ``benchmarks/fuzz.py``'s ``fbx`` reader, exported by Blender from the synthetic walk.

    python -c "import mocycle; from mocycle.datasets import synthetic_walk; \
               mocycle.write(synthetic_walk(n_frames=20, fps=30).motion, 'walk.bvh')"
    .venv-bpy52/bin/python benchmarks/fbx_seeds.py walk.bvh OUTDIR
    MOCYCLE_FUZZ_FBX=OUTDIR python benchmarks/fuzz.py --readers fbx

Runs in the bpy environment (``make .venv-bpy52/.installed``, which has no scipy: the BVH is made beforehand).
Writes a binary FBX of the walk (the armature alone), one with a skinned mesh, and one with two takes, the
first a still pose (the reader then bakes every take: the default is the first that moves, a leaf bone is an
End Site only when no take moves it).
"""

from __future__ import annotations

import sys
from pathlib import Path

import bpy


def main(bvh: Path, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert bpy.ops.import_anim.bvh(filepath=str(bvh), update_scene_fps=True, update_scene_duration=True) == {
        "FINISHED"}
    arm = bpy.context.active_object
    bpy.ops.export_scene.fbx(filepath=str(out / "walk.fbx"), bake_anim=True, add_leaf_bones=False)
    mesh = bpy.data.meshes.new("Body")
    mesh.from_pydata([tuple(b.head_local) for b in arm.data.bones], [], [])
    body = bpy.data.objects.new("Body", mesh)
    bpy.context.scene.collection.objects.link(body)
    body.parent = arm
    body.modifiers.new("Armature", "ARMATURE").object = arm
    for k, bone in enumerate(arm.data.bones):
        body.vertex_groups.new(name=bone.name).add([k], 1.0, "REPLACE")
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.export_scene.fbx(filepath=str(out / "walk_mesh.fbx"), bake_anim=True)
    walk = arm.animation_data.action
    walk.name = "walk"
    still = walk.copy()
    still.name = "Take 001"
    bags = [b for layer in getattr(still, "layers", []) for strip in layer.strips for b in strip.channelbags]
    for fc in [fc for b in bags for fc in b.fcurves] or list(getattr(still, "fcurves", [])):
        hold = fc.keyframe_points[0].co.y
        for key in fc.keyframe_points:
            key.co.y = key.handle_left.y = key.handle_right.y = hold
    still.use_fake_user = True
    bpy.ops.export_scene.fbx(filepath=str(out / "walk_two_takes.fbx"), bake_anim=True, bake_anim_use_all_actions=True,
                             add_leaf_bones=False)
    print("\n".join(f"{p}: {p.stat().st_size} bytes" for p in sorted(out.glob("*.fbx"))))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
