"""mocycle for Blender: periodic motion extraction where animators work.

Operators ``bpy.ops.mocycle.find_phase``, ``extract_cycle``, ``blend_cycles``, ``transition`` and ``stretch``
read the active armature's action, call ``mocycle.tasks`` and write new actions; the panel is in the 3D view's
sidebar, tab "mocycle". The add-on holds no algorithm: ``rig`` converts armature + action ⇄ ``mocycle.Motion``,
``channels`` speaks both generations of Blender's animation API.
"""

from __future__ import annotations

import bpy

from . import operators, panel, props

CLASSES = props.CLASSES + operators.CLASSES + panel.CLASSES


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.mocycle = bpy.props.PointerProperty(type=props.MOCYCLE_PG_state)


def unregister():
    del bpy.types.Scene.mocycle
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
