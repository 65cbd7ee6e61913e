"""The operators: read the active armature's action, call ``mocycle.tasks``, write new actions. No algorithm."""

from __future__ import annotations

import json

import bpy

from mocycle import tasks
from mocycle.errors import MocycleError
from mocycle.tasks.clips import closing_frame
from mocycle.tasks.spec import SPECS

from . import props, rig


def _armature(context):
    arm = context.active_object
    if arm is None or arm.type != "ARMATURE":
        raise MocycleError("select an armature (the active object is not one)")
    if arm.animation_data is None or arm.animation_data.action is None:
        raise MocycleError(f"armature {arm.name!r} has no active action")
    return arm


def _selected_bones(arm) -> list[str]:
    """Bones selected in Pose Mode (5.0 keeps the flag on the pose bone, earlier versions on the bone)."""
    def selected(pb):
        flag = getattr(pb, "select", None)
        return pb.bone.select if flag is None else flag
    return [pb.name for pb in arm.pose.bones if selected(pb) and not pb.bone.hide]


def _joints(op, arm) -> str | None:
    """The thesis' options 25-26: in Pose Mode the selected bones carry the phase (None: the task decides)."""
    if op.selected_bones and arm.mode == "POSE":
        names = _selected_bones(arm)
        if names:
            return ",".join(names)
    return None


def _frame_range(op, action) -> tuple[int, int, str | None]:
    """(first frame read, last frame read, the task's START:STOP over those frames or None)."""
    first, last = rig.action_frames(action)
    if not op.use_frame_range:
        return first, last, None
    start, end = max(op.frame_start, first), min(op.frame_end, last)
    if end <= start:
        raise MocycleError(f"frame range {op.frame_start}..{op.frame_end} leaves no frames of {action.name!r} "
                           f"({first}..{last})")
    return first, last, f"{start - first}:{end - first + 1}"


def _actions(arm, first, other: str) -> list:
    names = [n.strip() for n in other.split(",") if n.strip()]
    missing = [n for n in names if n not in bpy.data.actions]
    if missing:
        raise MocycleError(f"no action named {', '.join(map(repr, missing))}")
    return [first] + [bpy.data.actions[n] for n in names]


def _state(context):
    return context.scene.mocycle


def _record(context, task: str, action, period=-1.0, seam=-1.0, skate=-1.0, message="") -> None:
    st = _state(context)
    st.last_task, st.last_action = task, action.name if action else ""
    st.last_period, st.last_seam, st.last_skate, st.last_message = period, seam, skate, message


def _keep_parts(context, parts: list[dict], first: int) -> None:
    """The action's steady parts (``tasks.loop`` facts) in the panel's list, in the action's frame numbers."""
    st = _state(context)
    picked = st.part_index
    st.parts.clear()
    for p in parts:
        item = st.parts.add()
        a, b = p["frames"]
        item.kind, item.frames, item.loops = p["kind"], f"{a + first}-{b + first - 1}", p["loop"]
        item.period_frames = p["period_frames"] or 0.0
        item.n_periods = p["n_periods"] or 0.0
        item.reason = p["reason"] or ""
    st.part_index = picked if 0 <= picked < len(st.parts) else -1


def _keep_facts(action, report) -> None:
    action["mocycle"] = json.dumps({"task": report.task, **report.facts}, default=str)


class _Task(bpy.types.Operator):
    """Shared run/report of the operators; subclasses implement ``work(context, arm) -> str``."""

    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "ARMATURE"

    def execute(self, context):
        try:
            arm = _armature(context)
            message = self.work(context, arm)
        except (MocycleError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        for w in getattr(self, "_warnings", ()):
            self.report({"WARNING"}, w)
        self.report({"INFO"}, message)
        return {"FINISHED"}


def _task_operator(task: str, idname: str, label: str, description: str, extra: dict, work):
    """The operator of a task: a property per field of the task's ``Options`` (from its spec,
    ``mocycle.tasks.spec.SPECS``) plus ``extra`` (what Blender itself supplies), and ``work``, which runs it."""
    options_cls = SPECS[task].options
    annotations = {**props.annotations(options_cls), **extra}
    return type(f"MOCYCLE_OT_{idname}", (_Task,), {
        "bl_idname": f"mocycle.{idname}", "bl_label": label, "bl_description": description,
        "__annotations__": annotations, "options_cls": options_cls, "work": work})


def _find_phase(self, context, arm):
    action = arm.animation_data.action
    first, last, window = _frame_range(self, action)
    motion = rig.to_motion(arm, action, (first, last))
    if window:
        a, b = (int(x) for x in window.split(":"))
        motion = motion[a:b]
    report = tasks.phase.run(motion, props.options_from(self.options_cls, self, joints=_joints(self, arm)))
    _keep_parts(context, report.facts["parts"], first)
    self._warnings = report.warnings
    found = report.facts["classes"]
    if not found:
        message = f"{action.name}: no part repeats ({report.facts['reason']})"
        _record(context, "find_phase", action, message=message)
        return message
    best = max(found, key=lambda c: c["n_periods"])
    message = (f"{action.name}: {len(report.facts['parts'])} part(s), {len(found)} repeat; the longest, part "
               f"{best['part']} ({best['kind']}): period {best['period_frames']:.1f} frames "
               f"({best['period_s']:.2f} s), {best['n_periods']:.1f} cycles")
    _record(context, "find_phase", action, period=best["period_frames"], message=message)
    return message


def _extract_cycle(self, context, arm):
    action = arm.animation_data.action
    first, last, window = _frame_range(self, action)
    motion = rig.to_motion(arm, action, (first, last))
    options = props.options_from(self.options_cls, self, frame_range=window, joints=_joints(self, arm),
                                 which=None if self.which < 0 else self.which)
    report = tasks.loop.run(motion, options)
    _keep_parts(context, report.facts["parts"], first)
    cycle, loop = report.result, report.motions["loop"]
    new = rig.write_action(arm, loop, f"{action.name}_cycle", first,
                           wrap=closing_frame(cycle, options.cycles, options.root), travel=options.root == "motion")
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    skate = f["feet"]["skate_after"] if f["feet"].get("skate_after") is not None else f["metrics"]["skate"]
    self._warnings = report.warnings
    a, b = f["frames"]
    part = "" if f.get("part") is None else f" ({f['kind']}, frames {a + first}-{b + first - 1})"
    message = (f"{new.name}{part}: period {f['period_frames']:.1f} frames, {f['cycle_frames']} frames a cycle × "
               f"{options.cycles}, seam {f['metrics']['seam_pose']:.2f}× median step, foot skate {skate:.3g}"
               f"; {f['reason']}")
    _record(context, "extract_cycle", new, f["period_frames"], f["metrics"]["seam_pose"], skate, message)
    return message


def _blend_cycles(self, context, arm):
    action = arm.animation_data.action
    actions = _actions(arm, action, self.other)
    if len(actions) < 2:
        raise MocycleError("blend needs at least one other action (Other actions)")
    motions = [rig.to_motion(arm, a) for a in actions]
    options = props.options_from(self.options_cls, self, which=None if self.which < 0 else self.which)
    report = tasks.blend.run(motions, options)
    result = report.result
    new = rig.write_action(arm, report.motions["loop"], f"{action.name}_blend", rig.action_frames(action)[0],
                           wrap=closing_frame(result, options.cycles, options.root), travel=options.root == "motion")
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    message = (f"{new.name}: blend of {', '.join(a.name for a in actions)}, period {f['period_frames']:.1f} "
               f"frames, seam {f['seam']['seam_pose']:.2f}× median step")
    _record(context, "blend_cycles", new, f["period_frames"], f["seam"]["seam_pose"], -1.0, message)
    return message


def _transition(self, context, arm):
    action = arm.animation_data.action
    actions = _actions(arm, action, self.other)
    if len(actions) != 2:
        raise MocycleError("transition needs exactly one other action (Other actions)")
    motions = [rig.to_motion(arm, a) for a in actions]
    options = props.options_from(self.options_cls, self, which=None if self.which < 0 else self.which)
    report = tasks.transition.run(motions, options)
    new = rig.write_action(arm, report.motions["transition"], f"{actions[0].name}_to_{actions[1].name}",
                           rig.action_frames(action)[0])
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    message = (f"{new.name}: {f['frames']} frames over {f['cycles']} cycles, period {f['period_frames_start']:.1f}"
               f" → {f['period_frames_end']:.1f} frames")
    _record(context, "transition", new, message=message)
    return message


def _stretch(self, context, arm):
    action = arm.animation_data.action
    first, last = rig.action_frames(action)
    motion = rig.to_motion(arm, action, (first, last))
    report = tasks.stretch.run(motion, props.options_from(self.options_cls, self))
    new = rig.write_action(arm, report.motions["stretched"], f"{action.name}_stretched", first)
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    skate = f["feet"].get("skate_after")
    message = f"{new.name}: {f['frames_in']} → {f['frames_out']} frames (factor {f['factor']:g})"
    _record(context, "stretch", new, skate=-1.0 if skate is None else skate, message=message)
    return message


def rig_assign(arm, action) -> None:
    """Make the new action the armature's active one (the source stays in the file, kept by a fake user)."""
    old = arm.animation_data.action
    if old is not None:
        old.use_fake_user = True
    rig.channels.assign(arm, action)


COMMON = props.COMMON
FindPhase = _task_operator("phase", "find_phase", "Find Phase", "The steady parts of the active action and the period "
                           "of each part that repeats, listed in the panel", COMMON, _find_phase)
ExtractCycle = _task_operator("loop", "extract_cycle", "Extract Cycle", "The typical cycle of the active action as a "
                              "new, looping action named <action>_cycle", {**COMMON, **props.WHICH}, _extract_cycle)
BlendCycles = _task_operator("blend", "blend_cycles", "Blend Cycles", "Blend the cycles of the active action and "
                             "other actions (weights) into a new looping action", {**props.WHICH, **props.OTHER},
                             _blend_cycles)
Transition = _task_operator("transition", "transition", "Transition", "A new action that starts as the active "
                            "action's cycle and ends as the other action's", {**props.WHICH, **props.OTHER},
                            _transition)
Stretch = _task_operator("stretch", "stretch", "Stretch", "The active action lengthened by a factor (time-frequency "
                         "warping of its periodic part) as a new action", {}, _stretch)


CLASSES = (FindPhase, ExtractCycle, BlendCycles, Transition, Stretch)
