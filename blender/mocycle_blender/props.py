"""Blender properties built from the task layer's ``tasks.schema(Options)`` (no defaults or help of their own),
and the panel's state on the scene."""


import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from mocycle import tasks

#: fields the add-on fills from Blender itself: the frame range from frame numbers, the phase joints from the
#: Pose Mode selection, the part from the list ``find_phase`` or ``extract_cycle`` made; AMC input and the take
#: of a glTF or FBX file never reach it (it reads the active action)
FROM_BLENDER = {"amc_fps", "frame_range", "joints", "which", "take"}
#: a value for fields the task requires (no default)
REQUIRED_DEFAULTS = {"factor": 1.5}


#: labels that say what a field is in the words of the panel, where its name would not ("classes" counts the
#: periodic motions looked for inside a part; the panel speaks of parts, not classes)
LABELS = {"classes": "Periodic motions"}


def _label(name: str) -> str:
    return LABELS.get(name, name.replace("_", " ").capitalize())


def schema_property(name: str, spec: dict):
    """One Blender property for one schema field: enum, int, float, bool, or text for mixed types."""
    help_ = spec.get("description", "")
    default = spec.get("default", REQUIRED_DEFAULTS.get(name))
    kind = spec.get("type")
    if kind == "string" and "enum" in spec:
        return EnumProperty(name=_label(name), description=help_, default=default,
                            items=[(v, v, "") for v in spec["enum"]])
    if kind == "integer":
        return IntProperty(name=_label(name), description=help_, default=default, min=spec.get("minimum", -2**31),
                           max=spec.get("maximum", 2**31 - 1))
    if kind == "number":
        low = spec.get("minimum", spec.get("exclusiveMinimum", -1e30))
        return FloatProperty(name=_label(name), description=help_, default=float(default),
                             min=float(low) + (1e-6 if "exclusiveMinimum" in spec else 0.0))
    if kind == "boolean":
        return BoolProperty(name=_label(name), description=help_, default=bool(default))
    text = "" if default is None else ",".join(map(str, default)) if isinstance(default, tuple) else str(default)
    return StringProperty(name=_label(name), description=help_ + " (empty: none)", default=text)


def annotations(options_cls) -> dict:
    """Blender property annotations for the fields of a task's ``Options`` (apart from ``FROM_BLENDER``)."""
    props = tasks.schema(options_cls)["properties"]
    return {k: schema_property(k, v) for k, v in props.items() if k not in FROM_BLENDER}


def option_names(options_cls) -> list[str]:
    return [k for k in tasks.schema(options_cls)["properties"] if k not in FROM_BLENDER]


def options_from(options_cls, source, **extra):
    """``options_cls(...)`` from the same-named attributes of ``source`` (an operator or a property group);
    empty text means None; ``extra`` sets the fields Blender fills."""
    values = {}
    for k in option_names(options_cls):
        v = getattr(source, k)
        values[k] = None if isinstance(v, str) and not v.strip() else v
    values.update({k: v for k, v in extra.items() if v is not None})
    return options_cls(**values)


def copy_options(options_cls, source, target) -> None:
    for k in option_names(options_cls):
        setattr(target, k, getattr(source, k))


def range_key(source) -> str:
    """The frames an operator reads (``source``: the operator or the panel's state, both with the ``COMMON``
    settings), as the parts list remembers them: ``""`` for all the action's frames, else ``"START..END"``."""
    if not getattr(source, "use_frame_range", False):
        return ""
    return f"{source.frame_start}..{source.frame_end}"


def _group(name: str, options_cls, more: dict | None = None):
    return type(name, (bpy.types.PropertyGroup,), {"__annotations__": {**annotations(options_cls), **(more or {})}})


#: settings shared by the operators that read the active action (the thesis' options 6-9 and 26)
COMMON = {
    "use_frame_range": BoolProperty(name="Frame range", description="Use only frames Start..End of the action"),
    "frame_start": IntProperty(name="Start", description="First frame used", default=1),
    "frame_end": IntProperty(name="End", description="Last frame used", default=250),
    "selected_bones": BoolProperty(
        name="Selected bones", default=True,
        description="In Pose Mode, find the phase on the selected bones only (all bones are animated)"),
}
WHICH = {"which": IntProperty(name="Part", default=-1, min=-1,
                              description="Which part of the action (0-based, as the panel lists them after Find "
                                          "Phase or Extract Cycle; -1: the steady part with the most cycles)")}
OTHER = {"other": StringProperty(name="Other actions", description="Names of the other action(s), "
                                 "comma-separated (the active action comes first)")}

PhaseSettings = _group("MOCYCLE_PG_phase", tasks.phase.Options)
LoopSettings = _group("MOCYCLE_PG_loop", tasks.loop.Options)
BlendSettings = _group("MOCYCLE_PG_blend", tasks.blend.Options)
TransitionSettings = _group("MOCYCLE_PG_transition", tasks.transition.Options)
StretchSettings = _group("MOCYCLE_PG_stretch", tasks.stretch.Options)


class MOCYCLE_PG_part(bpy.types.PropertyGroup):
    """One steady part of the action that Find Phase or Extract Cycle found (walk straight, turning, run, arms,
    ...)."""

    kind: StringProperty(name="Kind")
    frames: StringProperty(name="Frames")
    period_frames: FloatProperty(name="Period (frames)")
    n_periods: FloatProperty(name="Cycles")
    loops: BoolProperty(name="Loops")
    reason: StringProperty(name="Why not looped")


#: the panel's settings and the last result, on the scene (saved and undone with it)
MOCYCLE_PG_state = type("MOCYCLE_PG_state", (bpy.types.PropertyGroup,), {"__annotations__": {
    "phase": PointerProperty(type=PhaseSettings),
    "loop": PointerProperty(type=LoopSettings),
    "blend": PointerProperty(type=BlendSettings),
    "transition": PointerProperty(type=TransitionSettings),
    "stretch": PointerProperty(type=StretchSettings),
    **COMMON,
    "other_action": PointerProperty(type=bpy.types.Action, name="Other action",
                                    description="The second action of Blend and Transition"),
    "other_weight": FloatProperty(name="Weight of the other", default=0.5, min=0.0, max=1.0),
    "parts": CollectionProperty(type=MOCYCLE_PG_part),
    "part_index": IntProperty(name="Part", default=-1),
    # whose parts the list holds: the action and the frame range read ("" for all its frames)
    "parts_action": StringProperty(),
    "parts_range": StringProperty(),
    # the last run, whether it worked or not: one short line, its figures with units, the technical detail
    "last_task": StringProperty(),
    "last_action": StringProperty(),
    "last_ok": BoolProperty(default=True),
    "last_period": FloatProperty(default=-1.0),
    "last_seam": FloatProperty(default=-1.0),
    "last_skate": FloatProperty(default=-1.0),
    "last_message": StringProperty(),
    "last_figures": StringProperty(),
    "last_detail": StringProperty(),
}})


CLASSES = (PhaseSettings, LoopSettings, BlendSettings, TransitionSettings, StretchSettings,
           MOCYCLE_PG_part, MOCYCLE_PG_state)
