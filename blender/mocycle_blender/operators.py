"""The operators: read the active armature's action, call ``mocycle.tasks``, write new actions. No algorithm."""

from __future__ import annotations

import bpy

from mocycle import tasks
from mocycle.errors import LoopRefused, MocycleError, OptionError
from mocycle.tasks import words
from mocycle.tasks.clips import closing_frame
from mocycle.tasks.loop import METRIC_LABELS
from mocycle.tasks.report import Labelled
from mocycle.tasks.spec import SPECS
from mocycle.text import json_text

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


# ------------------------------------------------------------------------------------- what a run says
class Said:
    """What a run says: ``message`` (one short line: the status bar, the panel's last result), ``figures``
    (``"Period: 30.0 frames (1.00 s)"``, each with its unit, none ``nan``) and ``detail`` (the technical lines:
    the library's own words, each check's reason with its numbers; the panel's Details and the Info editor)."""

    def __init__(self, message: str, figures=(), detail=()):
        self.message, self.figures, self.detail = words.brief(message), list(figures), list(detail)


#: how the library's words number frames, said in the detail whenever a text from it names frames
FRAMES_NOTE = "(frame numbers in mocycle's own words count from 0 at the first frame read: Blender frame {first})"


#: what "--force writes it anyway" is in Blender
FORCE = "Force (Advanced, under Cycle, Blend or Transition) writes it anyway, with a warning naming the failed checks"


def _frames(a: int, b: int, first: int) -> str:
    """Take frames ``a..b`` (stop excluded, 0 at ``first``) as Blender frame numbers, both ends included."""
    return f"frames {a + first}-{b + first - 1}"


def _part(d: dict, first: int) -> str:
    """``part 2 (gesture, frames 138-161)`` of a part's facts (``part`` or its index, ``kind``, ``frames``)."""
    return f"part {d['part']} ({d['kind']}, {_frames(*d['frames'], first)})"


def _seconds(frames, fps) -> str:
    text = words.number(frames, 1, "frames")
    if text is None:
        return "not measured"
    s = words.number(float(frames) / float(fps), 2, "s") if fps else None
    return f"{text} ({s})" if s else text


def _speed(context, value) -> str:
    """A speed in Blender units per second in the scene's units (``1.23 cm/s``); ``not measured`` for none."""
    if words.number(value) is None:
        return "not measured"
    units = context.scene.unit_settings
    if units.system == "NONE":
        return f"{float(value):.3g} units/s"
    return bpy.utils.units.to_string(units.system, "LENGTH", float(value) * units.scale_length, precision=3) + "/s"


def _seam(value) -> str:
    text = words.number(value, 2, "× a frame's step")
    return "not measured" if text is None else f"{text} (about 1 is seamless)"


def _parts_detail(parts: list[dict], first: int) -> list[str]:
    lines = []
    for k, p in enumerate(parts):
        what = (f"{p['n_periods']:.1f} cycles of {p['period_frames']:.1f} frames"
                if p["loop"] and words.number(p.get("period_frames")) and words.number(p.get("n_periods"))
                else p["reason"] or "does not loop")
        lines.append(f"{_part({'part': k, **p}, first)}: {what}")
    return lines


def _with_note(lines: list[str], first: int | None) -> list[str]:
    if first is not None and any("frames " in line for line in lines):
        lines = lines + [FRAMES_NOTE.format(first=first)]
    return lines


def _nothing(reason: str, parts: list[dict]) -> str:
    """Why nothing loops, short: the library's reason (the CLI's words) unless it names frames, which the
    parts list shows in Blender's numbers."""
    if "frames " not in reason:
        return reason
    if len(parts) == 1 and parts[0]["reason"]:
        return parts[0]["reason"]
    return f"none of its {len(parts)} parts loops (the parts list says why for each)"


def _failure(op, exc) -> Said:
    """What a failed run says: a short line from the structured facts when the task left them (``tasks.loop``'s
    refusals: the part, its frames in Blender's numbers, the failed checks in plain words), else the message
    itself, cut to a line; the whole message and every check's reason in the detail."""
    action, first = getattr(op, "_action", None), getattr(op, "_first", None)
    name = f"{action.name}: " if action is not None else ""
    text = words.hints(" ".join(str(exc).split()))  # a hint ("option 'force'") as the option's name, not a flag
    if isinstance(exc, OptionError):  # the option as the operator labels it
        prop = op.rna_type.properties.get(exc.parameter)
        text = f"{prop.name if prop else exc.parameter}: {exc.reason}"
        return Said(name + text, detail=[text])
    force = [FORCE] if isinstance(exc, LoopRefused) else []
    facts = getattr(exc, "facts", None)
    if facts and first is not None:
        out, parts = facts.get("not_looped", []), facts.get("parts", [])
        picked = getattr(op, "which", -1)
        # the parts that were tried and did not loop: the one picked, else each that should have looped
        tried = [d for d in out if (d["part"] == picked if picked >= 0 else
                                    d["part"] < len(parts) and parts[d["part"]]["loop"])]
        checks = [f"{_part(d, first)}, check {c['check']}: {c['reason']} (measured {c['value']:.3g}, limit "
                  f"{c['limit']:.3g})" for d in out for c in d.get("failed_checks", [])]
        # a refusal's own message repeats the checks' lines (with frames counted from the range read): left out
        detail = checks if checks and facts.get("status") == "refused" else [text, *checks]
        if tried:
            d = tried[0]
            why = (f"is {words.refusal(d['failed_checks'])}" if d.get("failed_checks") else
                   f"does not loop: {d['reason']}")
            message = f"{name}{_part(d, first)} {why}"
        else:
            message = name + _nothing(words.hints(facts.get("reason") or text), parts)
        return Said(message, detail=_with_note(detail + _parts_detail(parts, first) + force, first))
    if isinstance(exc, LoopRefused) and exc.failed:  # blend, transition: which action's cycle, and why
        labels = sorted((a.name for a in getattr(op, "_actions", ())), key=len, reverse=True)
        who = next((a for a in labels if text.startswith(a)), action.name if action is not None else "")
        checks = [f"check {c.name}: {c.reason} (measured {c.value:.3g}, limit {c.limit:.3g})" for c in exc.failed]
        return Said(f"{who}: {words.refusal(exc.failed)}" if who else words.refusal(exc.failed),
                    detail=[text, *checks, *force])
    message = text if action is None or text.startswith(action.name) else name + text
    return Said(message, detail=_with_note([text, *force], first))


def _show(context, task: str, action, said: Said, ok: bool, period=-1.0, seam=-1.0, skate=-1.0) -> None:
    """The panel's last result: this run's, whether it worked or not (nothing of the run before is kept)."""
    st = _state(context)
    st.last_task, st.last_action, st.last_ok = task, action.name if action else "", ok
    st.last_message = said.message
    st.last_figures = "\n".join(said.figures)
    st.last_detail = "\n".join(said.detail)
    st.last_period, st.last_seam = period, seam
    st.last_skate = skate if words.number(skate) is not None else -1.0


def _keep_parts(context, parts: list[dict], first: int, action, frames: str) -> None:
    """The action's steady parts (``tasks.loop`` or ``tasks.phase`` facts) in the panel's list, in the action's
    frame numbers; the list remembers whose parts they are (the action and the frame range read), so that a
    part picked in it is passed on only for that action and range."""
    st = _state(context)
    same = st.parts_action == action.name and st.parts_range == frames
    picked = st.part_index if same else -1
    st.parts.clear()
    for p in parts:
        item = st.parts.add()
        item.kind, item.frames, item.loops = p["kind"], _frames(*p["frames"], first)[7:], p["loop"]
        item.period_frames = p["period_frames"] if words.number(p.get("period_frames")) else 0.0
        item.n_periods = p["n_periods"] if words.number(p.get("n_periods")) else 0.0
        item.reason = words.brief(p["reason"] or "")
    st.parts_action, st.parts_range = action.name, frames
    st.part_index = picked if 0 <= picked < len(st.parts) else -1


def _drop_parts(context) -> None:
    st = _state(context)
    st.parts.clear()
    st.part_index = -1
    st.parts_action = st.parts_range = ""


def _keep_facts(action, report) -> None:
    """The task's figures on the new action, as strict JSON (a figure that could not be measured is null)."""
    action["mocycle"] = json_text({"task": report.task, **report.facts}, indent=None)


class _Task(bpy.types.Operator):
    """Shared run/report of the operators; subclasses implement ``work(context, arm) -> Said``.

    Whatever happens the panel shows this run: its result, or why it failed (the parts list refilled from the
    failed run's facts when it left them, else emptied unless it lists the parts of the action and frames this
    run read)."""

    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "ARMATURE"

    def execute(self, context):
        self._action = self._first = None
        self._frames = props.range_key(self)
        self._actions = ()
        try:
            arm = _armature(context)
            self._action = arm.animation_data.action
            said = self.work(context, arm)
        except (MocycleError, ValueError) as exc:
            said = _failure(self, exc)
            facts = getattr(exc, "facts", None)
            st = _state(context)
            if facts and facts.get("parts") is not None and self._first is not None:
                _keep_parts(context, facts["parts"], self._first, self._action, self._frames)
            elif not (self._action is not None and st.parts_action == self._action.name
                      and st.parts_range == self._frames):
                _drop_parts(context)
            _show(context, self._idname, self._action, said, ok=False)
            if len(said.detail) > 1 or (said.detail and said.detail[0] != said.message):
                self.report({"INFO"}, "mocycle details: " + " | ".join(said.detail))
            self.report({"ERROR"}, said.message)
            return {"CANCELLED"}
        for w in getattr(self, "_warnings", ()):
            self.report({"WARNING"}, words.brief(words.hints(w)))
        self.report({"INFO"}, said.message)
        return {"FINISHED"}


def _task_operator(task: str, idname: str, label: str, description: str, extra: dict, work):
    """The operator of a task: a property per field of the task's ``Options`` (from its spec,
    ``mocycle.tasks.spec.SPECS``) plus ``extra`` (what Blender itself supplies), and ``work``, which runs it."""
    options_cls = SPECS[task].options
    annotations = {**props.annotations(options_cls), **extra}
    return type(f"MOCYCLE_OT_{idname}", (_Task,), {
        "bl_idname": f"mocycle.{idname}", "bl_label": label, "bl_description": description,
        "__annotations__": annotations, "options_cls": options_cls, "work": work, "_idname": idname})


def _find_phase(self, context, arm):
    action = arm.animation_data.action
    first, last, window = _frame_range(self, action)
    self._first = first
    motion = rig.to_motion(arm, action, (first, last))
    if window:
        a, b = (int(x) for x in window.split(":"))
        motion = motion[a:b]
        self._first = first + a  # frame 0 of the task is the range's first frame
    report = tasks.phase.run(Labelled(motion, action.name),
                             props.options_from(self.options_cls, self, joints=_joints(self, arm)))
    f, base = report.facts, self._first
    _keep_parts(context, f["parts"], base, action, self._frames)
    self._warnings = report.warnings
    found, parts = f["classes"], f["parts"]
    detail = _with_note([f["reason"], *_parts_detail(parts, base),
                         *(f"part {c['part']} period: {c['period_reason']}" for c in found), *report.warnings], base)
    if not found:
        message = f"{action.name}: {_nothing(f['reason'], parts)}"
        said = Said(message, detail=detail)
        _show(context, "find_phase", action, said, ok=False)
        return said
    best = max(found, key=lambda c: c["n_periods"])
    fps = best["period_frames"] / best["period_s"] if words.number(best.get("period_s")) else None
    figures = [f"Period: {_seconds(best['period_frames'], fps)}",
               f"Cycles: {words.number(best['n_periods'], 1) or 'not measured'}"]
    message = (f"{action.name}: {len(parts)} part(s), {len(found)} repeat(s); the most cycles: "
               f"{_part(best, base)}, a period of {_seconds(best['period_frames'], fps)}")
    said = Said(message, figures, detail)
    _show(context, "find_phase", action, said, ok=True, period=best["period_frames"])
    return said


def _extract_cycle(self, context, arm):
    action = arm.animation_data.action
    first, last, window = _frame_range(self, action)
    self._first = first
    motion = rig.to_motion(arm, action, (first, last))
    options = props.options_from(self.options_cls, self, frame_range=window, joints=_joints(self, arm),
                                 which=None if self.which < 0 else self.which)
    report = tasks.loop.run(Labelled(motion, action.name), options)
    f = report.facts
    _keep_parts(context, f["parts"], first, action, self._frames)
    cycle, loop = report.result, report.motions["loop"]
    new = rig.write_action(arm, loop, f"{action.name}_cycle", first,
                           wrap=closing_frame(cycle, options.cycles, options.root), travel=options.root == "motion")
    _keep_facts(new, report)
    rig_assign(arm, new)
    skate = words.written_skate(f["feet"], f["metrics"])
    self._warnings = report.warnings
    others = sum(1 for p in f["parts"] if p["loop"]) - 1
    why = ("the part picked" if options.which is not None else
           "the take's one part" if len(f["parts"]) == 1 else "the part with the most cycles"
           + (f"; {others} other part(s) loop too: pick one in the parts list" if others > 0 else ""))
    figures = [f"Period: {_seconds(f['period_frames'], f['fps'])}",
               f"Loop: {f['cycle_frames']} frames × {options.cycles}",
               f"Seam: {_seam(f['metrics']['seam_pose'])}",
               f"Foot skate: {_speed(context, skate)}"]
    failed = f.get("failed_checks") or []
    message = (f"{new.name}: {_part(f, first)}, {why}; a loop of {f['cycle_frames']} frames "
               f"({f['cycle_frames'] / f['fps']:.2f} s)"
               f"{'' if options.cycles == 1 else f' × {options.cycles}'}"
               + (f" ({words.refusal(failed)}, kept because forced)" if failed else ""))
    metrics = report.facts["metrics"]
    detail = [f["reason"], f"period: {f['period_reason']}",
              *(f"{label}: {words.number(metrics.get(k), 4, unit) or 'not measured'}"
                for k, (label, unit) in METRIC_LABELS.items()),
              *(f"check {c['check']}: {c['reason']}" for c in failed), *report.warnings,
              *_parts_detail(f["parts"], first)]
    said = Said(message, figures, _with_note(detail, first))
    _show(context, "extract_cycle", new, said, True, f["period_frames"], f["metrics"]["seam_pose"],
          -1.0 if skate is None else skate)
    return said


def _blend_cycles(self, context, arm):
    action = arm.animation_data.action
    actions = _actions(arm, action, self.other)
    self._actions = actions
    if len(actions) < 2:
        raise MocycleError("blend needs at least one other action (Other actions)")
    motions = [Labelled(rig.to_motion(arm, a), a.name) for a in actions]
    options = props.options_from(self.options_cls, self, which=None if self.which < 0 else self.which)
    report = tasks.blend.run(motions, options)
    result = report.result
    new = rig.write_action(arm, report.motions["loop"], f"{action.name}_blend", rig.action_frames(action)[0],
                           wrap=closing_frame(result, options.cycles, options.root), travel=options.root == "motion")
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    fps = context.scene.render.fps / context.scene.render.fps_base
    skate = f["feet"].get("skate_after")
    figures = [f"Period: {_seconds(f['period_frames'], fps)}", f"Seam: {_seam(f['seam']['seam_pose'])}"] + (
        [f"Foot skate: {_speed(context, skate)}"] if skate is not None else [])
    message = (f"{new.name}: blend of {', '.join(a.name for a in actions)}, a period of "
               f"{_seconds(f['period_frames'], fps)}")
    said = Said(message, figures, [message, *report.warnings])
    _show(context, "blend_cycles", new, said, True, f["period_frames"], f["seam"]["seam_pose"],
          -1.0 if skate is None else skate)
    return said


def _transition(self, context, arm):
    action = arm.animation_data.action
    actions = _actions(arm, action, self.other)
    self._actions = actions
    if len(actions) != 2:
        raise MocycleError("transition needs exactly one other action (Other actions)")
    motions = [Labelled(rig.to_motion(arm, a), a.name) for a in actions]
    options = props.options_from(self.options_cls, self, which=None if self.which < 0 else self.which)
    report = tasks.transition.run(motions, options)
    new = rig.write_action(arm, report.motions["transition"], f"{actions[0].name}_to_{actions[1].name}",
                           rig.action_frames(action)[0])
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    fps = context.scene.render.fps / context.scene.render.fps_base
    figures = [f"Length: {_seconds(f['frames'], fps)}, {f['cycles']} cycles",
               f"Period: {_seconds(f['period_frames_start'], fps)} → {_seconds(f['period_frames_end'], fps)}"]
    message = (f"{new.name}: {f['frames']} frames over {f['cycles']} cycles, the period going from "
               f"{words.number(f['period_frames_start'], 1, 'frames')} to "
               f"{words.number(f['period_frames_end'], 1, 'frames')}")
    said = Said(message, figures, [message, *report.warnings])
    _show(context, "transition", new, said, True)
    return said


def _stretch(self, context, arm):
    action = arm.animation_data.action
    first, last = rig.action_frames(action)
    self._first = first
    motion = rig.to_motion(arm, action, (first, last))
    report = tasks.stretch.run(Labelled(motion, action.name), props.options_from(self.options_cls, self))
    new = rig.write_action(arm, report.motions["stretched"], f"{action.name}_stretched", first)
    _keep_facts(new, report)
    rig_assign(arm, new)
    f = report.facts
    self._warnings = report.warnings
    skate = f["feet"].get("skate_after")
    figures = [f"Length: {f['frames_in']} → {f['frames_out']} frames (× {f['factor']:g})"] + (
        [f"Foot skate: {_speed(context, skate)}"] if skate is not None else [])
    message = f"{new.name}: {f['frames_in']} → {f['frames_out']} frames (factor {f['factor']:g})"
    said = Said(message, figures, [message, *report.warnings])
    _show(context, "stretch", new, said, True, skate=-1.0 if skate is None else skate)
    return said


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


class MOCYCLE_OT_copy_details(bpy.types.Operator):
    """Copy the last run's message and technical detail to the clipboard"""

    bl_idname = "mocycle.copy_details"
    bl_label = "Copy Details"

    @classmethod
    def poll(cls, context):
        return bool(context.scene.mocycle.last_detail)

    def execute(self, context):
        st = _state(context)
        context.window_manager.clipboard = f"{st.last_message}\n{st.last_detail}"
        self.report({"INFO"}, "mocycle: details copied")
        return {"FINISHED"}


CLASSES = (FindPhase, ExtractCycle, BlendCycles, Transition, Stretch, MOCYCLE_OT_copy_details)
