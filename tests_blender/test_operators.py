"""Every operator on BVH takes imported with ``bpy.ops.import_anim.bvh``: new actions of the right length that
loop (Blender's own evaluation, Cycles modifiers included), the options reaching the task, errors, undo."""

import json

import bpy
import numpy as np
import pytest

from conftest import import_bvh, shared_path

FPS = 30


def heads(arm, frame) -> np.ndarray:
    """World positions of every bone head at ``frame``, as Blender evaluates the armature."""
    bpy.context.scene.frame_set(frame)
    return np.array([np.array(arm.matrix_world @ pb.head) for pb in arm.pose.bones])


def local_rotations(arm, frame) -> np.ndarray:
    bpy.context.scene.frame_set(frame)
    return np.array([np.array(pb.matrix_basis.to_quaternion()) for pb in arm.pose.bones])


def size(arm) -> float:
    return float(np.ptp(heads(arm, 1), axis=0).max())


def facts(action) -> dict:
    return json.loads(action["mocycle"])


def write_take(tmp_path, name, make, **kw):
    import mocycle

    path = tmp_path / f"{name}.bvh"
    mocycle.write(make(fps=FPS, **kw).motion, path)
    return path


@pytest.fixture
def walk(scene, tmp_path):
    """A synthetic walk (1 s period, 8 periods at 30 fps) imported from BVH: armature 'Walk', action 'Walk'."""
    from mocycle.datasets import synthetic_walk

    return import_bvh(write_take(tmp_path, "Walk", synthetic_walk, n_frames=240))


@pytest.fixture
def run_action(walk, tmp_path):
    """A synthetic run (0.7 s) on the same skeleton: action 'Run' (its armature is deleted, the action kept)."""
    from mocycle.datasets import synthetic_run

    other = import_bvh(write_take(tmp_path, "Run", synthetic_run, n_frames=200))
    action = other.animation_data.action
    action.use_fake_user = True
    bpy.data.objects.remove(other)
    bpy.context.view_layer.objects.active = walk
    walk.select_set(True)
    return action


def check_loop(arm, action, period_frames, cycles=1, inplace=True):
    """The action is a clean loop: its length is the period (× cycles) within one frame, the pose after its last
    frame is its first, and the Cycles modifiers carry that on beyond the keys."""
    start, end = (int(round(x)) for x in action.frame_range)
    length = end - start
    f = facts(action)
    assert length == f["cycle_frames"] * cycles
    assert abs(length - period_frames * cycles) <= 1.0
    assert action.use_cyclic
    fcurves = bpy.context.active_object and addon_fcurves(arm, action)
    assert fcurves and all(any(m.type == "CYCLES" for m in fc.modifiers) for fc in fcurves)
    scale = size(arm)
    if inplace:
        jump = np.abs(heads(arm, end) - heads(arm, start)).max() / scale       # frame last + 1 == first
        beyond = np.abs(heads(arm, end + 3) - heads(arm, start + 3)).max() / scale
    else:  # the body loops; the root travels on
        jump = np.abs(local_rotations(arm, end)[1:] - local_rotations(arm, start)[1:]).max()
        beyond = np.abs(local_rotations(arm, end + 3)[1:] - local_rotations(arm, start + 3)[1:]).max()
    print(f"\n{action.name}: {length} frames (period {period_frames:.2f}), seam pose difference {jump:.1e}")
    assert jump <= 1e-5 and beyond <= 1e-5
    return start, end


def addon_fcurves(arm, action):
    import sys

    return sys.modules["bl_ext.user_default.mocycle"].channels.fcurves(arm, action)


def test_find_phase(walk):
    assert bpy.ops.mocycle.find_phase() == {"FINISHED"}
    st = bpy.context.scene.mocycle
    assert len(st.parts) >= 1 and st.part_index == -1  # nothing picked yet
    looping = [p for p in st.parts if p.loops]
    assert looping[0].period_frames == pytest.approx(FPS, rel=0.03)
    assert looping[0].n_periods == pytest.approx(8, abs=0.5)
    assert st.last_task == "find_phase" and "repeat" in st.last_message


def test_extract_cycle_loops(walk):
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    action = walk.animation_data.action
    assert action.name == "Walk_cycle" and "Walk" in bpy.data.actions
    f = facts(action)
    assert f["period_frames"] == pytest.approx(FPS, abs=1.0)
    check_loop(walk, action, f["period_frames"])
    st = bpy.context.scene.mocycle
    assert st.last_period == pytest.approx(f["period_frames"]) and st.last_seam >= 0 and st.last_skate >= 0
    one_liner(st.last_message)
    assert st.last_ok and st.last_message.endswith(f"a loop of {f['cycle_frames']} frames "
                                                   f"({f['cycle_frames'] / FPS:.2f} s)"), st.last_message


def test_extract_cycle_root_motion_repeated(walk):
    assert bpy.ops.mocycle.extract_cycle(root="motion", cycles=2) == {"FINISHED"}
    action = walk.animation_data.action
    f = facts(action)
    start, end = check_loop(walk, action, f["period_frames"], cycles=2, inplace=False)
    root = [heads(walk, k)[0] for k in (start, end, 2 * end - start)]
    stride = np.linalg.norm(root[1] - root[0])
    assert stride == pytest.approx(2 * np.linalg.norm(f["travel_per_cycle"]), rel=0.05)  # two cycles walked
    assert np.abs((root[2] - root[1]) - (root[1] - root[0])).max() <= 1e-3 * stride  # and on beyond the keys


def test_extract_cycle_options_reach_the_task(walk):
    """Method, model, K, subsampling, frame range, the Pose Mode selection and the feet clean-up."""
    walk.select_set(True)
    bpy.ops.object.mode_set(mode="POSE")
    legs = [pb for pb in walk.pose.bones if "Leg" in pb.name or "Foot" in pb.name]
    for pb in walk.pose.bones:
        flag = pb in legs
        if hasattr(pb, "select"):
            pb.select = flag
        else:
            pb.bone.select = flag
    # step: a text field (empty: about 30 frames a second, the task's default)
    assert bpy.ops.mocycle.extract_cycle(method="harmonic", model="M2", harmonics="6", step="2",
                                         use_frame_range=True, frame_start=31, frame_end=210, feet="lock",
                                         root="motion") == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    f = facts(walk.animation_data.action)
    assert f["model"] == "M2" and f["harmonics"] == 6
    assert f["frames_in"] == 180
    assert set(f["joints_used"].split(",")) == {pb.name for pb in legs}
    assert f["feet"]["mode"] == "lock"
    # the cycle is now the active action: one cycle (with its closing key), a clip looped as it is
    period = f["cycle_frames"]
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    again = facts(walk.animation_data.action)
    assert again["method"] == "clip" and again["cycle_frames"] == period
    walk.animation_data.action = bpy.data.actions["Walk"]
    assert bpy.ops.mocycle.extract_cycle(method="centroid") == {"FINISHED"}
    assert facts(walk.animation_data.action)["method"] == "centroid"


def test_which_part_from_the_list(walk):
    bpy.ops.mocycle.find_phase()
    assert bpy.ops.mocycle.extract_cycle(which=0) == {"FINISHED"}
    assert facts(walk.animation_data.action)["part"] == 0
    with pytest.raises((RuntimeError, TypeError), match="which|part"):
        bpy.ops.mocycle.extract_cycle(which=7)


def test_an_fbx_imported_by_blender_loops(walk, tmp_path):
    """Blender's own FBX importer, then Extract Cycle: the action loops (issue 31: "import a BVH and an FBX,
    extract a cycle")."""
    path = tmp_path / "walk.fbx"
    assert bpy.ops.export_scene.fbx(filepath=str(path), use_selection=False, bake_anim=True,
                                    add_leaf_bones=False) == {"FINISHED"}
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    assert bpy.ops.import_scene.fbx(filepath=str(path)) == {"FINISHED"}
    arm = next(ob for ob in bpy.data.objects if ob.type == "ARMATURE")
    bpy.context.view_layer.objects.active = arm
    arm.select_set(True)
    assert arm.animation_data and arm.animation_data.action
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    f = facts(arm.animation_data.action)
    assert f["period_frames"] == pytest.approx(FPS, rel=0.05)
    check_loop(arm, arm.animation_data.action, f["period_frames"])


def test_extract_cycle_lists_the_parts_and_loops_the_one_picked(scene, tmp_path):
    """A walk that turns mid-take (issue 28): the panel lists its parts; the part picked is the one looped."""
    from mocycle.datasets import synthetic_walk_turn_walk

    arm = import_bvh(write_take(tmp_path, "Turn", synthetic_walk_turn_walk, turn_deg=90.0, seed=4))
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    st = bpy.context.scene.mocycle
    kinds = [p.kind for p in st.parts if p.loops]  # between them a short transition may be listed, not looped
    runs = [k for i, k in enumerate(kinds) if i == 0 or k != kinds[i - 1]]  # a straight walk may come in two parts
    assert runs == ["walk straight", "walk turning left", "walk straight"], kinds
    assert all(p.reason for p in st.parts if not p.loops)
    assert "(walk" in st.last_message and "the part with the most cycles" in st.last_message
    arm.animation_data.action = bpy.data.actions["Turn"]
    turning = next(k for k, p in enumerate(st.parts) if p.kind == "walk turning left")
    assert bpy.ops.mocycle.extract_cycle(which=turning, root="motion") == {"FINISHED"}
    f = facts(arm.animation_data.action)
    assert f["part"] == turning and f["kind"] == "walk turning left" and f["turn_per_cycle_deg"] > 20


def test_blend_cycles(walk, run_action):
    assert bpy.ops.mocycle.blend_cycles(other="Run", weights="0.5,0.5") == {"FINISHED"}
    action = walk.animation_data.action
    assert action.name == "Walk_blend"
    f = facts(action)
    assert 0.7 * FPS < f["period_frames"] < 1.0 * FPS  # between the run's and the walk's
    check_loop(walk, action, f["period_frames"])


def test_transition(walk, run_action):
    assert bpy.ops.mocycle.transition(other="Run", cycles=3) == {"FINISHED"}
    action = walk.animation_data.action
    assert action.name == "Walk_to_Run"
    start, end = (int(round(x)) for x in action.frame_range)
    assert end - start + 1 == facts(action)["frames"]


def test_stretch(walk):
    assert bpy.ops.mocycle.stretch(factor=1.5) == {"FINISHED"}
    action = walk.animation_data.action
    assert action.name == "Walk_stretched"
    start, end = (int(round(x)) for x in action.frame_range)
    assert end - start + 1 == facts(action)["frames_out"] == 360


def test_no_periodic_motion_is_refused(scene, tmp_path):
    from mocycle.datasets import synthetic_nonperiodic

    arm = import_bvh(write_take(tmp_path, "Wander", synthetic_nonperiodic, n_frames=240))
    before = set(bpy.data.actions.keys())
    with pytest.raises(RuntimeError, match="(?i)periodic|repeat"):
        bpy.ops.mocycle.extract_cycle()
    assert set(bpy.data.actions.keys()) == before and arm.animation_data.action.name == "Wander"


def test_needs_an_armature(scene):
    bpy.ops.object.add(type="EMPTY")
    assert not bpy.ops.mocycle.extract_cycle.poll()


def test_undo_restores_the_original(walk):
    """Headless Blender keeps an undo stack: a step before, the operator called as the UI calls it (its own undo
    step: ``bpy.ops`` pushes one only when asked, the second positional argument), then ``ed.undo``."""
    bpy.ops.ed.undo_push(message="before mocycle")
    assert bpy.ops.mocycle.extract_cycle("EXEC_DEFAULT", True) == {"FINISHED"}
    assert bpy.data.objects["Walk"].animation_data.action.name == "Walk_cycle"
    assert bpy.ops.ed.undo() == {"FINISHED"}
    arm = bpy.data.objects["Walk"]  # undo reloads the data: old references are gone
    assert arm.animation_data.action.name == "Walk"
    assert "Walk_cycle" not in bpy.data.actions
    assert bpy.context.scene.mocycle.last_task == ""


@pytest.mark.shared_data
def test_real_walk(scene):
    """A CMU walk on the 100-joint Character Creator rig (60 fps): the loop's length is its period."""
    arm = import_bvh(shared_path("cmu-iclone", "07_01.bvh"))
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    f = facts(arm.animation_data.action)
    check_loop(arm, arm.animation_data.action, f["period_frames"])


# ------------------------------------------------------------------------------- what the panel says (issue 37)
def said(st) -> str:
    """Everything the panel shows of the last run: its line, its figures, its details and the parts list."""
    rows = [f"{p.kind} {p.frames} {p.reason}" for p in st.parts]
    return "\n".join([st.last_message, st.last_figures, st.last_detail, *rows])


def one_liner(text: str) -> None:
    assert text and "\n" not in text and len(text) <= 160, text
    assert "class" not in text.lower() and "nan" not in text.lower().split(), text
    assert text.endswith(" …") or text.count("(") == text.count(")"), text


def test_a_failed_run_clears_the_previous_result(walk, tmp_path):
    """Find Phase on a walk fills the list and the last result; a failed run on another take shows that take's
    failure and its parts, nothing of the walk's; a failure that leaves no parts empties the list."""
    from mocycle.datasets import synthetic_nonperiodic

    st = bpy.context.scene.mocycle
    assert bpy.ops.mocycle.find_phase() == {"FINISHED"} and st.parts and st.last_period > 0
    wander = import_bvh(write_take(tmp_path, "Wander", synthetic_nonperiodic, n_frames=240))
    with pytest.raises(RuntimeError) as caught:
        bpy.ops.mocycle.extract_cycle()
    one_liner(str(caught.value).removeprefix("Error: ").strip())
    assert st.last_task == "extract_cycle" and st.last_action == "Wander" and not st.last_ok
    assert "Walk" not in said(st) and "Wander" in st.last_message and "repeat" in st.last_message
    assert st.last_period == st.last_seam == st.last_skate == -1.0 and st.last_figures == ""
    assert st.parts_action == "Wander" and [p.kind for p in st.parts] == ["gesture"] and not st.parts[0].loops
    # a failure with no parts to show (an action that does not exist): the list is emptied, not the walk's
    bpy.context.view_layer.objects.active = walk
    assert bpy.ops.mocycle.find_phase() == {"FINISHED"} and st.parts_action == "Walk"
    bpy.context.view_layer.objects.active = wander
    with pytest.raises(RuntimeError, match="no action named"):
        bpy.ops.mocycle.blend_cycles(other="Nope")
    assert len(st.parts) == 0 and st.parts_action == "" and st.last_action == "Wander" and "Walk" not in said(st)


def test_the_part_picked_is_said_in_plain_words(scene, tmp_path):
    """Picking a part that does not loop (a gesture between a walk and a wave) and pressing Extract says which
    part, its frames in Blender's numbers and why, in a line; a part picked in another action's list is not
    passed on."""
    from mocycle.datasets import synthetic_walk_then_wave

    arm = import_bvh(write_take(tmp_path, "WalkWave", synthetic_walk_then_wave))
    st = bpy.context.scene.mocycle
    assert bpy.ops.mocycle.find_phase() == {"FINISHED"}
    one_liner(st.last_message)
    k = next(k for k, p in enumerate(st.parts) if not p.loops)
    p = st.parts[k]
    first = int(round(arm.animation_data.action.frame_range[0]))
    with pytest.raises(RuntimeError) as caught:
        bpy.ops.mocycle.extract_cycle(which=k)
    message = str(caught.value).removeprefix("Error: ").strip()
    one_liner(message)
    assert f"part {k} ({p.kind}, frames {p.frames}) does not loop: " in message and p.reason in message
    assert int(p.frames.split("-")[0]) >= first and st.part_index == -1 and len(st.parts) > 1
    # the panel passes the part picked for this action and these frames only
    st.part_index = k
    assert panel_which(arm) == k
    st.use_frame_range = True  # other frames: another list
    assert panel_which(arm) == -1
    st.use_frame_range = False
    arm.animation_data.action = bpy.data.actions.new("Other")  # another action
    assert panel_which(arm) == -1


def panel_which(arm) -> int:
    """The part the panel's Extract Cycle button passes (its ``which``), from the panel's own ``draw()``."""
    import sys

    layout = docs_figures().Recorder()
    sys.modules["bl_ext.user_default.mocycle"].panel.MOCYCLE_PT_panel.draw(type("P", (), {"layout": layout})(),
                                                                           bpy.context)
    (button,) = [i for i in _flatten(layout.to_json()) if i.get("button") == "Extract Cycle"]
    return button["options"]["which"]


def test_figures_have_units_and_no_nan(scene, tmp_path):
    """A rig whose feet are not found by name: its foot skate cannot be measured and is said so, never as
    ``nan``; the period has frames and seconds, the skate of a walk whose feet are found Blender's length unit
    per second; the action's facts are strict JSON (null, not NaN)."""
    import mocycle
    from mocycle.datasets import synthetic_walk
    from mocycle.motion import Motion, Skeleton

    m = synthetic_walk(n_frames=240, fps=FPS).motion
    s = m.skeleton
    plain = Skeleton(tuple(f"b{j}" for j in range(s.n_joints)), s.parents, s.offsets, s.channels,
                     end_sites=s.end_sites)
    path = tmp_path / "Rig.bvh"
    mocycle.write(Motion(plain, m.rotations, m.translations, m.frame_time), path)
    arm = import_bvh(path)
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    st = bpy.context.scene.mocycle
    one_liner(st.last_message)
    assert "nan" not in said(st).lower().replace("nance", "")  # (no "nan" word or number anywhere)
    figures = st.last_figures.split("\n")
    assert any(t.startswith("Period: ") and " frames (" in t and t.endswith(" s)") for t in figures), figures
    assert "Foot skate: not measured" in figures and st.last_skate == -1.0
    assert "foot skate, cycle (as fitted): not measured" in st.last_detail
    text = arm.animation_data.action["mocycle"]
    assert "NaN" not in text and json.loads(text)["metrics"]["skate"] is None
    # a walk whose feet are found: the skate in the scene's length unit per second
    walk = import_bvh(write_take(tmp_path, "Walk", synthetic_walk, n_frames=240))
    bpy.context.view_layer.objects.active = walk
    assert bpy.ops.mocycle.extract_cycle() == {"FINISHED"}
    skate = next(t for t in st.last_figures.split("\n") if t.startswith("Foot skate: "))
    assert skate.endswith("m/s") and st.last_skate >= 0, skate


@pytest.fixture
def limp(scene, tmp_path):
    """A 500-frame walk whose phase is replaced, while the test runs, by the phase of a walk 1.5 times slower
    (as in tests/studio/test_studio_refusal.py): its cycle fails the fit and stride checks and is refused."""
    import mocycle
    import mocycle.cycle.parts as parts_module
    from mocycle.datasets import synthetic_walk
    from mocycle.phase import find_phase

    path = tmp_path / "Limp.bvh"
    mocycle.write(synthetic_walk(n_frames=500, fps=FPS, noise_deg=1.0, seed=1).motion, path)
    wrong = find_phase(synthetic_walk(n_frames=500, fps=FPS, period_s=1.5, noise_deg=1.0, seed=4).motion)
    real = parts_module.part_phase
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(parts_module, "part_phase", lambda part: wrong if part.n_frames == 500 else real(part))
        yield import_bvh(path)


def test_a_refusal_is_one_line_with_its_detail_one_click_away(limp):
    """The refusal's line names the part in Blender's frames and the failed checks in plain words; the
    technical reason of each check, with its numbers, is in the Details sub-panel (and the Info editor)."""
    st = bpy.context.scene.mocycle
    with pytest.raises(RuntimeError) as caught:
        bpy.ops.mocycle.extract_cycle()
    message = str(caught.value).removeprefix("Error: ").strip()
    one_liner(message)
    assert message.startswith("Limp: part 0 (walk straight, frames 1-500) is not a loop: ") and "--force" not in message
    assert message == st.last_message and not st.last_ok
    assert "check fit: the cycle fits the take" in st.last_detail and "limit" in st.last_detail
    addon = __import__("sys").modules["bl_ext.user_default.mocycle"]
    layout = docs_figures().Recorder()
    addon.panel.MOCYCLE_PT_details.draw(type("P", (), {"layout": layout})(), bpy.context)
    text = json.dumps(layout.to_json())
    assert "Copy Details" in text and "check fit" in text
    lines = [i["label"] for i in _flatten(layout.to_json()) if "label" in i]
    assert lines and max(map(len, lines)) <= 80  # wrapped to the sidebar, not one 600-character label
    assert "Force (Advanced" in st.last_detail
    assert bpy.ops.mocycle.copy_details() == {"FINISHED"}  # (headless Blender has no clipboard to read back)


def docs_figures():
    """``blender/docs_figures.py``, whose ``Recorder`` stands in for Blender's layout to record what a panel
    draws."""
    import importlib.util

    from conftest import REPO

    spec = importlib.util.spec_from_file_location("docs_figures", REPO / "blender" / "docs_figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _flatten(node):
    for item in node["items"]:
        if "items" in item:
            yield from _flatten(item)
        else:
            yield item


def test_find_phase_numbers_the_parts_of_the_frames_read(walk):
    """With a frame range, the parts list gives Blender's frame numbers (the range's first frame is the first
    part's), and remembers the range: the panel passes a part picked in it only while the same range is set."""
    st = bpy.context.scene.mocycle
    assert bpy.ops.mocycle.find_phase(use_frame_range=True, frame_start=31, frame_end=210) == {"FINISHED"}
    assert st.parts[0].frames.startswith("31-") and st.parts[-1].frames.endswith("-210"), [p.frames for p in st.parts]
    assert st.parts_action == "Walk" and st.parts_range == "31..210"
    assert "frames 31-" in st.last_message
