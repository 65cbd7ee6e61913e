"""The sidebar panel (3D view, tab "mocycle"): the options of each task, the parts found, the last result in
a few short lines, and its technical detail in the Details sub-panel (closed by default).  Each button runs its
operator with the panel's settings."""

from __future__ import annotations

import textwrap

import bpy

from mocycle import tasks

from . import props

#: options drawn under "Advanced" (the thesis' options 16-24); the rest are always shown
ADVANCED = {"classes", "pca", "delay", "min_periods", "n_landmarks", "time_axis", "harmonics", "force",
            "foot_joints", "align", "window_frames"}


class MOCYCLE_UL_parts(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        what = (f"{item.n_periods:.1f} cycles of {item.period_frames:.1f} frames" if item.loops and item.n_periods
                else item.reason or "does not loop")
        layout.label(text=f"{index}: {item.kind}, frames {item.frames}: {what}",
                     icon="CHECKMARK" if item.loops else "BLANK1")


def parts_are_of(st, action) -> bool:
    """The parts list holds the parts of ``action`` over the frames the operators would read now."""
    return action is not None and len(st.parts) > 0 and st.parts_action == action.name and \
        st.parts_range == props.range_key(st)


def wrapped(layout, context, text: str, icon: str = "NONE") -> None:
    """``text`` as labels, a line each, wrapped to the sidebar's width (a label is one line in Blender)."""
    region = getattr(context, "region", None)
    width = max(24, int((region.width if region else 420) / 7))
    first = True
    for paragraph in text.split("\n"):
        for line in textwrap.wrap(paragraph, width) or [""]:
            layout.label(text=line, icon=icon if first else "BLANK1" if icon != "NONE" else "NONE")
            first = False


def _options(layout, group, options_cls, advanced: bool):
    for name in props.option_names(options_cls):
        if (name in ADVANCED) == advanced:
            layout.prop(group, name)


def _button(layout, idname, text, group, options_cls, st, extra=(), action=None):
    op = layout.operator(idname, text=text)
    props.copy_options(options_cls, group, op)
    for k in extra:
        if k == "which":  # the part picked in the list, when the list is the active action's over these frames
            picked = 0 <= st.part_index < len(st.parts) and parts_are_of(st, action)
            op.which = st.part_index if picked else -1
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
            col = box.column()
            if parts_are_of(st, action):
                col.label(text=f"Parts of {st.parts_action}: pick one for the buttons below")
            else:  # another action's (or other frames'): shown, not used
                col.active = False
                other = "not the active action" if action is None or st.parts_action != action.name else \
                    "other frames"
                col.label(text=f"Parts of {st.parts_action} ({other}): not used", icon="INFO")
            col.template_list("MOCYCLE_UL_parts", "", st, "parts", st, "part_index", rows=3)

        box = layout.box()
        box.label(text="Cycle")
        _options(box, st.loop, tasks.loop.Options, advanced=False)
        _button(box, "mocycle.extract_cycle", "Extract Cycle", st.loop, tasks.loop.Options, st, common + ("which",),
                action)

        box = layout.box()
        box.label(text="Blend / Transition")
        box.prop(st, "other_action")
        box.prop(st, "other_weight")
        row = box.row()
        op = _button(row, "mocycle.blend_cycles", "Blend Cycles", st.blend, tasks.blend.Options, st, ("which", "other"),
                     action)
        op.weights = f"{1 - st.other_weight:g},{st.other_weight:g}"
        _button(row, "mocycle.transition", "Transition", st.transition, tasks.transition.Options, st,
                ("which", "other"), action)

        box = layout.box()
        box.label(text="Stretch")
        _options(box, st.stretch, tasks.stretch.Options, advanced=False)
        _button(box, "mocycle.stretch", "Stretch", st.stretch, tasks.stretch.Options, st)

        box = layout.box()
        box.label(text="Last result")
        if st.last_task:
            # one short line and the figures with their units; the technical detail is under Details
            wrapped(box, context, st.last_message, icon="CHECKMARK" if st.last_ok else "ERROR")
            for line in filter(None, st.last_figures.split("\n")):
                box.label(text=line)
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


class MOCYCLE_PT_details(bpy.types.Panel):
    """The last run's technical detail: the library's own words, each check's reason with its numbers, the
    warnings; the same text goes to the Info editor, and Copy Details puts it on the clipboard."""

    bl_label = "Details"
    bl_parent_id = "MOCYCLE_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "mocycle"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        st = context.scene.mocycle
        if not st.last_detail:
            self.layout.label(text="(no details: run an operator)")
            return
        self.layout.operator("mocycle.copy_details", text="Copy Details", icon="COPYDOWN")
        col = self.layout.column(align=True)
        for paragraph in st.last_detail.split("\n"):
            wrapped(col, context, paragraph)


CLASSES = (MOCYCLE_UL_parts, MOCYCLE_PT_panel, MOCYCLE_PT_details, MOCYCLE_PT_advanced)
