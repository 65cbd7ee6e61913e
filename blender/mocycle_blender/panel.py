"""The sidebar panel (3D view, tab "mocycle"): the options of each task, the parts found, the last result.
Each button runs its operator with the panel's settings."""

from __future__ import annotations

import bpy

from mocycle import tasks

from . import props

#: options drawn under "Advanced" (the thesis' options 16-24); the rest are always shown
ADVANCED = {"classes", "pca", "delay", "min_periods", "n_landmarks", "time_axis", "harmonics", "force",
            "foot_joints", "align", "window_frames"}


class MOCYCLE_UL_parts(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        what = f"{item.n_periods:.1f} × {item.period_frames:.1f} fr" if item.loops else item.reason
        layout.label(text=f"{index}: {item.kind} [{item.frames}]  {what}", icon="CHECKMARK" if item.loops else "BLANK1")


def _options(layout, group, options_cls, advanced: bool):
    for name in props.option_names(options_cls):
        if (name in ADVANCED) == advanced:
            layout.prop(group, name)


def _button(layout, idname, text, group, options_cls, st, extra=()):
    op = layout.operator(idname, text=text)
    props.copy_options(options_cls, group, op)
    for k in extra:
        if k == "which":  # a part of the action (the list Find Phase or Extract Cycle filled last)
            op.which = st.part_index if 0 <= st.part_index < len(st.parts) else -1
        elif k == "other":
            op.other = st.other_action.name if st.other_action else ""
        else:
            setattr(op, k, getattr(st, k))
    return op


class MOCYCLE_PT_panel(bpy.types.Panel):
    bl_label = "mocycle"
    bl_idname = "MOCYCLE_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "mocycle"

    def draw(self, context):
        layout, st = self.layout, context.scene.mocycle
        ob = context.active_object
        if ob is None or ob.type != "ARMATURE":
            layout.label(text="Select an armature with an action", icon="INFO")
            return
        action = ob.animation_data.action if ob.animation_data else None
        layout.label(text=f"{ob.name}: {action.name if action else 'no action'}", icon="ARMATURE_DATA")
        common = ("use_frame_range", "frame_start", "frame_end", "selected_bones")

        box = layout.box()
        box.label(text="Input")
        row = box.row(align=True)
        row.prop(st, "use_frame_range")
        sub = row.row(align=True)
        sub.enabled = st.use_frame_range
        sub.prop(st, "frame_start")
        sub.prop(st, "frame_end")
        box.prop(st, "selected_bones", text="Phase on selected bones (Pose Mode)")

        box = layout.box()
        box.label(text="Parts")
        _options(box, st.phase, tasks.phase.Options, advanced=False)
        _button(box, "mocycle.find_phase", "Find Phase", st.phase, tasks.phase.Options, st, common)
        if len(st.parts):  # the steady parts Find Phase or Extract Cycle found: pick one, the buttons below use it
            box.template_list("MOCYCLE_UL_parts", "", st, "parts", st, "part_index", rows=3)

        box = layout.box()
        box.label(text="Cycle")
        _options(box, st.loop, tasks.loop.Options, advanced=False)
        _button(box, "mocycle.extract_cycle", "Extract Cycle", st.loop, tasks.loop.Options, st, common + ("which",))

        box = layout.box()
        box.label(text="Blend / Transition")
        box.prop(st, "other_action")
        box.prop(st, "other_weight")
        row = box.row()
        op = _button(row, "mocycle.blend_cycles", "Blend Cycles", st.blend, tasks.blend.Options, st, ("which", "other"))
        op.weights = f"{1 - st.other_weight:g},{st.other_weight:g}"
        _button(row, "mocycle.transition", "Transition", st.transition, tasks.transition.Options, st,
                ("which", "other"))

        box = layout.box()
        box.label(text="Stretch")
        _options(box, st.stretch, tasks.stretch.Options, advanced=False)
        _button(box, "mocycle.stretch", "Stretch", st.stretch, tasks.stretch.Options, st)

        box = layout.box()
        box.label(text="Last result")
        if st.last_task:
            box.label(text=f"{st.last_task}: {st.last_action}")
            if st.last_period >= 0:
                box.label(text=f"Period: {st.last_period:.2f} frames")
            if st.last_seam >= 0:
                box.label(text=f"Seam: {st.last_seam:.2f} × median step")
            if st.last_skate >= 0:
                box.label(text=f"Foot skate: {st.last_skate:.3g} units/s")
        else:
            box.label(text="(nothing run yet)")


class MOCYCLE_PT_advanced(bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "MOCYCLE_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "mocycle"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        st = context.scene.mocycle
        for title, group, cls in (("Phase", st.phase, tasks.phase.Options), ("Cycle", st.loop, tasks.loop.Options),
                                  ("Blend", st.blend, tasks.blend.Options),
                                  ("Transition", st.transition, tasks.transition.Options),
                                  ("Stretch", st.stretch, tasks.stretch.Options)):
            box = self.layout.box()
            box.label(text=title)
            _options(box, group, cls, advanced=True)


CLASSES = (MOCYCLE_UL_parts, MOCYCLE_PT_panel, MOCYCLE_PT_advanced)
