"""Blender's animation API, both generations: F-curves of an action and new actions with keys written in bulk.

Blender 4.4+ stores F-curves in slotted (layered) actions: ``action.layers[].strips[].channelbags[]``, one
channelbag per slot; 5.0 removed the legacy ``action.fcurves``. 4.2/4.3 have only ``action.fcurves``.
"""

from __future__ import annotations

import bpy
import numpy as np

#: slotted actions and channelbags (4.4+) or the legacy ``action.fcurves`` (4.2, 4.3)
LAYERED = bpy.app.version >= (4, 4, 0)

#: ``Keyframe.interpolation`` enum index of 'LINEAR' (the order of ``rna_enum_beztriple_interpolation_mode``)
_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items.keys().index("LINEAR")


def _slot_for(obj, action):
    """The slot of ``action`` that animates ``obj``: the assigned one, else the first for objects."""
    ad = obj.animation_data
    if ad is not None and ad.action == action and getattr(ad, "action_slot", None) is not None:
        return ad.action_slot
    for slot in action.slots:
        if slot.target_id_type in {"OBJECT", "UNSPECIFIED"}:
            return slot
    return None


def fcurves(obj, action) -> list:
    """The F-curves of ``action`` that animate ``obj`` (an empty list when it has none)."""
    if not LAYERED:
        return list(action.fcurves)
    slot = _slot_for(obj, action)
    if slot is None:
        return []
    for layer in action.layers:
        for strip in layer.strips:
            bag = strip.channelbag(slot) if hasattr(strip, "channelbag") else None
            if bag is not None:
                return list(bag.fcurves)
    return []


def new_action(obj, name: str):
    """A new, empty action for ``obj``; returns ``(action, add)`` where ``add(data_path, index, group)`` makes
    an F-curve in it (in the slot for ``obj`` on 4.4+)."""
    action = bpy.data.actions.new(name)
    if not LAYERED:
        def add(path, index, group):
            return action.fcurves.new(path, index=index, action_group=group)
        return action, add
    slot = action.slots.new(id_type="OBJECT", name=obj.name)
    strip = action.layers.new("Layer").strips.new(type="KEYFRAME")
    bag = strip.channelbags.new(slot)

    def add(path, index, group):
        try:
            return bag.fcurves.new(path, index=index, group_name=group)
        except TypeError:  # 4.4/4.5: no group_name
            return bag.fcurves.new(path, index=index)
    return action, add


def assign(obj, action) -> None:
    """Make ``action`` the active action of ``obj`` (and its slot for ``obj`` on 4.4+)."""
    ad = obj.animation_data or obj.animation_data_create()
    ad.action = action
    if LAYERED and ad.action_slot is None:
        slot = _slot_for(obj, action)
        if slot is not None:
            ad.action_slot = slot


def write_keys(fcurve, frames: np.ndarray, values: np.ndarray) -> None:
    """Keys at ``frames (N,)`` with ``values (N,)``, linear, written in bulk (no per-key Python loop)."""
    n = len(frames)
    points = fcurve.keyframe_points
    points.add(n)
    co = np.empty((n, 2), dtype=np.float32)
    co[:, 0], co[:, 1] = frames, values
    points.foreach_set("co", co.ravel())
    points.foreach_set("interpolation", np.full(n, _LINEAR, dtype=np.int32))
    fcurve.update()


def sample(fcurve, frames: np.ndarray) -> np.ndarray:
    """The curve's values at integer ``frames (N,)``: read in bulk when the keys sit on exactly those frames
    (keys are passed through exactly), else evaluated frame by frame (modifiers and all)."""
    points = fcurve.keyframe_points
    n = len(points)
    if n == len(frames) and not len(fcurve.modifiers):
        co = np.empty(2 * n, dtype=np.float32)
        points.foreach_get("co", co)
        co = co.reshape(n, 2)
        if np.array_equal(co[:, 0], frames.astype(np.float32)):
            return co[:, 1].astype(np.float64)
    return np.array([fcurve.evaluate(float(f)) for f in frames])
