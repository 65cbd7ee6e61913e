"""Takes that change what they do (issue 28): steady parts, one loop per part, never an average.

Every take here is generated (``mocycle.datasets``) with its truth: the parts' frames, the heading per frame
and the period.  The loops are judged against that truth, not against the figures the code prints.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from mocycle.activities import segment_activities, short_period
from mocycle.cli import app
from mocycle.datasets import (
    synthetic_gesture,
    synthetic_run,
    synthetic_still,
    synthetic_walk,
    synthetic_walk_then_wave,
    synthetic_walk_turn_walk,
    synthetic_wave,
)
from mocycle.errors import MocycleError, NoPeriodicMotion
from mocycle.io import read, write

runner = CliRunner()


def _loops(take, tmp_path, *extra):
    src = write(take.motion, tmp_path / "take.bvh")
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "loop.bvh"), "--part", "all", "--root",
                                 "motion", "--json", *extra])
    return result, json.loads(result.stdout)


def _overlap(a, b) -> int:
    return max(0, min(a[1], b[1]) - max(a[0], b[0]))


@pytest.mark.parametrize("turn_deg, fps", [(90.0, 60.0), (-90.0, 30.0)])
def test_a_walk_that_turns_mid_take_gives_a_straight_a_turning_and_a_straight_loop(tmp_path, turn_deg, fps):
    take = synthetic_walk_turn_walk(turn_deg=turn_deg, fps=fps, seed=4)
    result, facts = _loops(take, tmp_path)
    assert result.exit_code == 0, result.output
    way = "left" if turn_deg > 0 else "right"
    assert [loop["kind"] for loop in facts["loops"]] == ["walk straight", f"walk turning {way}", "walk straight"]
    (_, b, c) = [s for s in take.segments if s[0].startswith("turning")][0]
    period = float(np.nanmedian(take.period_frames))
    for loop in facts["loops"]:
        frames = loop["frames"]
        assert abs(loop["period_frames"] / period - 1) < 0.08
        # never an average: a loop's frames lie in one truth segment, bar the blur of half a stride at a border
        inside = max(_overlap(frames, (s, e)) for _, s, e in take.segments)
        assert frames[1] - frames[0] - inside <= 0.5 * period
        # it turns per cycle as the take does over the frames it loops
        # (the take's turn read as its mean rate over those frames, or as a line through its heading: either)
        h = take.heading_deg[frames[0]:frames[1]]
        mean_rate = (h[-1] - h[0]) / (h.size - 1) * loop["period_frames"]
        line = np.polyfit(np.arange(h.size), h, 1)[0] * loop["period_frames"]
        got = loop["turn_per_cycle_deg"]
        assert min(abs(got - want) - max(10.0, 0.25 * abs(want)) for want in (mean_rate, line)) <= 0
        written = read(loop["output"])
        assert written.n_frames == loop["cycles"] * loop["cycle_frames"]
    turning = facts["loops"][1]
    a0, b0 = turning["frames"]  # the loop of the turn lies in the turn (its gentle ends may stay out)
    assert b - 0.5 * period <= a0 and b0 <= c + 0.5 * period and b0 - a0 >= 0.9 * period
    assert abs(turning["turn_per_cycle_deg"]) > 20 and np.sign(turning["turn_per_cycle_deg"]) == np.sign(turn_deg)
    assert "walk-turning" in turning["output"]


def test_the_default_loop_is_one_part_and_says_which_and_why(tmp_path):
    take = synthetic_walk_turn_walk(turn_deg=90.0, seed=5)
    src = write(take.motion, tmp_path / "take.bvh")
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "loop.bvh"), "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["status"] == "ok" and len(facts["loops"]) == 1 and (tmp_path / "loop.bvh").exists()
    chosen = facts["loops"][0]
    assert "the steady part with the most cycles" in facts["reason"] and chosen["part"] is not None
    assert chosen["period_frames"] == facts["period_frames"]  # the old flat figures are the chosen loop's
    assert [p["kind"] for p in facts["parts"] if p["loop"]] == ["walk straight", "walk turning left", "walk straight"]
    most = max(p["n_periods"] for p in facts["parts"])
    assert facts["parts"][chosen["part"]]["n_periods"] == most
    # the reason says what would write the others in the library's words; the terminal says it as a flag
    assert "(option 'part' = all writes every one)" in facts["reason"]
    table = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "again.bvh")])
    assert table.exit_code == 0 and "(--part all writes every one)" in table.stdout


@pytest.mark.parametrize("hand", ["right", "both"])
def test_a_wave_with_standing_legs_is_looped_at_the_arms_period(tmp_path, hand):
    take = synthetic_wave(hand=hand, seed=2)
    result, facts = _loops(take, tmp_path)
    assert result.exit_code == 0, result.output
    [loop] = facts["loops"]
    assert loop["kind"] == "arms" and abs(loop["period_frames"] / np.nanmedian(take.period_frames) - 1) < 0.08
    assert all(p["kind"] in ("arms", "gesture") for p in facts["parts"])


def test_a_walk_followed_by_a_wave_gives_two_parts(tmp_path):
    take = synthetic_walk_then_wave(seed=3)
    acts = segment_activities(take.motion)
    kinds = [p.kind for p in acts.loopable()]
    assert kinds == ["walk straight", "arms"]
    result, facts = _loops(take, tmp_path)
    assert result.exit_code == 0 and [loop["kind"] for loop in facts["loops"]] == ["walk straight", "arms"]


@pytest.mark.parametrize("fps, step", [(30.0, 1), (60.0, 2), (120.0, 4)])
def test_frames_without_gait_are_looked_at_about_30_times_a_second_unless_told(monkeypatch, tmp_path, fps, step):
    """The cohomology of a wave sees the same points on its circle at 120 fps as at 30 (``PHASE_RATE``): every
    fourth frame; ``--step 1`` still looks at every frame.  The arms are looped at their period either way."""
    from mocycle import activities

    assert activities.phase_step(fps) == step
    steps = []
    real = activities.find_phase_every

    def spy(motion, step=1, **options):
        steps.append(step)
        return real(motion, step, **options)

    monkeypatch.setattr(activities, "find_phase_every", spy)
    take = synthetic_wave(fps=fps, n_frames=int(6 * fps), seed=2)
    result, facts = _loops(take, tmp_path)
    assert result.exit_code == 0, result.output
    [loop] = facts["loops"]
    assert loop["kind"] == "arms" and abs(loop["period_frames"] / np.nanmedian(take.period_frames) - 1) < 0.08
    assert steps and set(steps) == {step}
    steps.clear()
    result, facts = _loops(take, tmp_path, "--step", "1")
    assert result.exit_code == 0 and steps and set(steps) == {1}


def test_frames_where_the_feet_land_are_looked_at_on_every_frame_unless_told():
    """A short gait found between gait parts must match its strides' period within a few percent over as few as
    1.2 cycles: every frame, not every fourth; a step asked for is taken everywhere."""
    from mocycle.activities import _phase_step_in

    assert _phase_step_in(None, 120.0) == 4 and _phase_step_in(None, 120.0, stepping=True) == 1
    assert _phase_step_in(3, 120.0) == 3 and _phase_step_in(3, 120.0, stepping=True) == 3
    assert _phase_step_in(None, 30.0) == 1


def test_a_take_of_one_and_a_third_periods_is_found_and_looped(tmp_path):
    take = synthetic_walk(n_frames=80, fps=60.0, period_s=1.0, noise_deg=1.0, seed=7)
    result, facts = _loops(take, tmp_path)
    assert result.exit_code == 0, result.output
    [loop] = facts["loops"]
    assert abs(loop["period_frames"] / 60.0 - 1) < 0.08 and loop["kind"] == "walk straight"
    # the period estimator for a short take: the legs' self-similarity near twice the step
    period, unlike = short_period(take.motion, 2 * 30.0, 0, 80)
    assert abs(period / 60.0 - 1) < 0.05 and unlike < 0.5


@pytest.mark.parametrize("make, words", [(lambda: synthetic_still(noise_deg=0.5), "stands still"),
                                         (lambda: synthetic_gesture(), "one gesture")])
def test_gestures_and_standing_are_never_looped_and_say_why_in_plain_words(tmp_path, make, words):
    result, facts = _loops(make(), tmp_path)
    assert result.exit_code == 3 and facts["status"] == "no-periodic-motion" and facts["loops"] == []
    assert words in facts["reason"] and words in result.stderr
    assert not list(tmp_path.glob("loop*.bvh"))


def test_no_prime_lifting_the_class_falls_back_to_the_next_joints(monkeypatch):
    """The lift of the cocycle to Z can fail on a capture (a 30 fps run); the legs, then the arms are tried."""
    from mocycle.phase import analysis, find_phase

    real_fit = analysis.CohomologyFit.fit
    calls = []

    def failing_first(self, X):
        calls.append(X.shape)
        if len(calls) == 1:
            raise MocycleError("could not lift the cohomology class to integer coefficients with any prime tried")
        return real_fit(self, X)

    monkeypatch.setattr(analysis.CohomologyFit, "fit", failing_first)
    walk = synthetic_walk(n_frames=300, fps=30.0, period_s=1.0, noise_deg=1.0, seed=1).motion
    result = find_phase(walk)
    assert result.joints_used == "legs" and result.classes and "could not lift" in result.reason
    monkeypatch.setattr(analysis.CohomologyFit, "fit", lambda self, X: (_ for _ in ()).throw(
        MocycleError("could not lift the cohomology class to integer coefficients with any prime tried")))
    with pytest.raises(NoPeriodicMotion, match="could not lift"):
        find_phase(walk)


def test_a_loop_off_the_strides_or_the_takes_turn_is_refused():
    """The stride and turn checks: a cycle fitted at a wrong period (a phase that runs 30 % slow) fails both."""
    from dataclasses import replace

    from mocycle.activities import line_periodic
    from mocycle.cycle import extract_cycle
    from mocycle.cycle.parts import part_checks, part_phase, part_piece

    take = synthetic_walk_turn_walk(turn_deg=90.0, seed=6)
    motion = take.motion
    acts = segment_activities(motion)
    k, right = [(k, p) for k, p in enumerate(acts.parts) if p.kind == "walk turning left"][0]
    piece = motion[right.start:right.stop]
    wrong = 1.3 * right.period_frames
    pm = line_periodic(np.arange(piece.n_frames) / wrong, wrong, motion.frame_time, "test", "legs", "a wrong period")
    cycle = extract_cycle(piece, phase=part_phase(replace(right, periodic=pm, period_frames=wrong)))
    failed = {f.name for f in part_checks(part_piece(motion, acts, k), cycle)}
    assert "stride" in failed
    good = extract_cycle(piece, phase=part_phase(right))
    assert part_checks(part_piece(motion, acts, k), good) == []


def test_stride_phase_keeps_the_run_of_alternating_feet_inside_the_part():
    """A landing of the same foot twice in a row (another gait's chain beside the part) starts a new run; the
    stride line is drawn through the run holding the part, so its period stays the part's own."""
    from mocycle.activities import Activity, stride_phase

    part = Activity(start=100, stop=400, kind="walk straight", limbs="legs", period_frames=100.0)
    frames = np.array([100, 150, 200, 250, 300, 350, 400, 420])  # 420: the left foot again, 20 frames on
    foot = np.array([0, 1, 0, 1, 0, 1, 0, 0])
    x, period = stride_phase(part, frames, foot, 100, 400)
    assert period == pytest.approx(100.0)
    assert x[0] == pytest.approx(0.0, abs=1e-9) and x[-1] == pytest.approx(299 / 100.0)
    # without the filter the extra landing would count as a step: the line would bend
    x2, period2 = stride_phase(part, frames[:-1], foot[:-1], 100, 400)
    assert period2 == pytest.approx(period)


def test_stride_phase_leaves_out_a_step_unlike_the_others():
    """A step across a join (the other foot's landing of the take before, alternating by chance, almost two steps
    before the part's first landing) starts a new run: the line goes through the part's own steps."""
    from mocycle.activities import Activity, stride_phase

    part = Activity(start=100, stop=300, kind="run straight", limbs="legs", period_frames=42.0)
    own = 120 + 21 * np.arange(9)  # a run: a step every 21 frames
    frames = np.r_[own[0] - 40, own]  # 80: the last landing before the join, 40 frames (1.9 steps) back
    foot = np.arange(frames.size) % 2
    _, period = stride_phase(part, frames, foot, 100, 400)
    assert period == pytest.approx(42.0)
    # a step of 1.4 steps counted as one would have bent the line (the period over 4 % long)
    B = np.column_stack([np.ones(frames.size), np.arange(frames.size) / 2.0, foot != foot[0]])
    bent = np.linalg.lstsq(B, frames.astype(float), rcond=None)[0][1]
    assert bent > 1.04 * 42.0


def test_stride_phase_takes_a_landing_outside_the_part_only_at_its_tempo():
    """A 30 fps run whose feet land every 10.5 frames, and the next take's first landing 16 frames after its last
    (a blend: under STEP_RATIO of the median step, so the run of landings holds it): the line through it made
    the run's period 22.3 frames where its feet land every 21, and the loop was refused as 6 % off its strides.
    A landing outside the part carries the phase to the part's edge only when it steps at the part's tempo."""
    from mocycle.activities import Activity, stride_phase

    part = Activity(start=0, stop=64, kind="run straight", limbs="legs", period_frames=21.0)
    own = np.round(3 + 10.5 * np.arange(6))  # 3, 14 (13.5), 24, 34, 45, 56
    foot = np.arange(own.size + 1) % 2
    blend = np.r_[own, own[-1] + 16]
    _, period = stride_phase(part, blend, foot, 0, 64)
    assert period == pytest.approx(21.0, rel=0.01)
    B = np.column_stack([np.ones(blend.size), np.arange(blend.size) / 2.0, foot != foot[0]])
    assert np.linalg.lstsq(B, blend.astype(float), rcond=None)[0][1] > 1.04 * 21.0  # the line through it bends
    # a landing just outside at the part's tempo still carries the phase (the same period as without it)
    steady = np.r_[own, own[-1] + 10]
    _, p2 = stride_phase(part, steady, foot, 0, 64)
    assert p2 == pytest.approx(21.0, rel=0.02)


def _steps(motion):
    from mocycle.activities import find_landings

    return find_landings(motion)


def test_a_walk_too_short_to_be_seen_repeating_loops_when_its_feet_land_a_period_apart():
    """A stretch whose chain of landings broke (a landing missed) is looked at without gait: 1.9 strides are too
    few to be seen to repeat on their own (MIN_REPEATS), but the feet landing a stride apart see it repeat."""
    from mocycle.activities import _decide, _other

    fps, period = 60.0, 1.0
    walk = synthetic_walk(n_frames=int(1.9 * period * fps), fps=fps, period_s=period, noise_deg=0.5, seed=3).motion
    options = {"joints": None, "step": 1}
    blind = _other(walk, 0, walk.n_frames, 1.2, True, options)
    _decide(blind, 1.2)
    assert not any(p.loop for p in blind)
    seen = _other(walk, 0, walk.n_frames, 1.2, True, options, steps=_steps(walk))
    _decide(seen, 1.2)
    looped = [p for p in seen if p.loop]
    assert len(looped) == 1 and looped[0].in_step, [(p.kind, p.reason) for p in seen]
    assert looped[0].kind == "walk straight"  # named by its feet
    assert looped[0].period_frames == pytest.approx(period * fps, rel=0.08)
    assert "the feet landing a period apart" in looped[0].reason


def _repeat_found_in_a_walk(monkeypatch, period_share: float, landings_of):
    """The parts :func:`_other` makes of 1.6 strides of a 1 s walk at 60 fps where the cohomology "finds" a repeat
    at ``period_share`` of the stride, the feet's landings being ``landings_of(the walk's landings)``."""
    import mocycle.activities as A

    fps, period = 60.0, 1.0
    walk = synthetic_walk(n_frames=int(1.6 * period * fps), fps=fps, period_s=period, noise_deg=0.5, seed=3).motion
    P = period_share * period * fps
    found = A.line_periodic(np.arange(walk.n_frames) / P, P, walk.frame_time, "cohomology", "all", "found")
    monkeypatch.setattr(A, "_periodic_in", lambda *args, **kwargs: ("all", "periodic", found, (0, walk.n_frames)))
    return A._other(walk, 0, walk.n_frames, 1.2, True, {"joints": None, "step": 1}, steps=landings_of(_steps(walk)))


@pytest.mark.parametrize("period_share, loops", [(0.4, False), (1.0, True)])
def test_a_repeat_found_where_the_feet_step_but_make_no_stride_is_checked_by_the_legs(monkeypatch, period_share,
                                                                                     loops):
    """Frames of a walk without a stride of landings (a step or two only, at the end of a walk-turn-walk take in a
    session): a repeat the cohomology finds there at 0.4 of the stride (the legs swap sides by then) is no loop
    of the walk, one at the stride is."""
    import mocycle.activities as A

    def two_steps(steps):
        first = int(np.flatnonzero(steps.foot != steps.foot[0])[0])
        two = A.Landings(steps.frames[first - 1:first + 1], steps.foot[first - 1:first + 1], steps.sides, steps.down)
        assert A._foot_periods(two, 0, steps.down.size, 60.0).size == 0  # two steps: no stride to be in step with
        return two

    parts = _repeat_found_in_a_walk(monkeypatch, period_share, two_steps)
    assert [p.loop for p in parts] == [loops], [(p.kind, p.reason) for p in parts]
    if not loops:
        assert parts[0].kind == "transition" and "unlike themselves" in parts[0].reason


@pytest.mark.parametrize("period_share, loops", [(0.25, False), (1.0, True)])
def test_a_repeat_found_where_the_legs_move_but_no_foot_lands_is_checked_by_the_legs(monkeypatch, period_share,
                                                                                    loops):
    """A shuffle's last steps, where the feet lift too little to land (no landing within the frames): a repeat
    found there at a quarter of the stride (a 1.2 s stride "looped" at 0.3 s) is no loop, one at the stride is;
    the legs move, so the whole body repeats only where they do."""
    import mocycle.activities as A

    def no_landing(steps):
        return A.Landings(steps.frames[:0], steps.foot[:0], steps.sides, steps.down)

    parts = _repeat_found_in_a_walk(monkeypatch, period_share, no_landing)
    assert [p.loop for p in parts] == [loops], [(p.kind, p.reason) for p in parts]
    if not loops:
        assert parts[0].kind == "transition" and "the legs move but are unlike themselves" in parts[0].reason


def test_a_walk_running_off_without_a_chain_of_landings_is_not_looped_across_the_change():
    """Frames without a gait part where a short walk turns into a run: looked at blind, the whole body "repeats"
    across both, but the legs, which move, are unlike themselves a period later, so no loop holds a walk and a run;
    with the landings, the part that loops lies in one gait."""
    from mocycle.activities import _decide, _other
    from mocycle.datasets import join_takes

    fps = 60.0
    s = join_takes([synthetic_walk(n_frames=90, fps=fps, period_s=1.0, noise_deg=0.5, seed=1).motion,
                    synthetic_run(n_frames=84, fps=fps, period_s=0.7, noise_deg=0.5, seed=3).motion], ["walk", "run"])
    m = s.motion

    def spans(parts):  # loops reaching beyond their main stretch by more than half a period
        out = []
        for p in (p for p in parts if p.loop):
            over = [max(0, min(p.stop, e) - max(p.start, a)) for _, a, e in s.stretches]
            if sum(over) - max(over) > 0.5 * p.period_frames:
                out.append((p.start, p.stop))
        return out

    options = {"joints": None, "step": 1}
    blind = _other(m, 0, m.n_frames, 1.2, True, options)
    _decide(blind, 1.2)
    seen = _other(m, 0, m.n_frames, 1.2, True, options, steps=_steps(m))
    _decide(seen, 1.2)
    assert not spans(blind) and any("the legs move but are unlike themselves" in p.reason for p in blind)
    assert not spans(seen), [(p.kind, p.start, p.stop, p.reason) for p in seen]
    assert any(p.loop for p in seen)


def test_a_wave_loop_ends_where_the_wave_ends_not_in_the_slow_gesture_after_it():
    """An arm raised at an even pace has a velocity alike itself a period later although nothing repeats: the wave
    before it must not reach into it (the poses must come back a period later)."""
    from mocycle.datasets import join_takes

    fps = 60.0
    takes = [synthetic_wave(n_frames=int(5 * fps), fps=fps, hand="right", wave_period_s=0.6, seed=4).motion,
             synthetic_gesture(n_frames=int(3 * fps), fps=fps, seed=5).motion]
    s = join_takes(takes, ["wave", "gesture"])
    border = s.stretches[0][2]
    arms = [p for p in segment_activities(s.motion).loopable() if p.kind == "arms"]
    assert len(arms) == 1
    assert arms[0].stop - border <= 0.5 * arms[0].period_frames, (arms[0].stop, border, arms[0].period_frames)


def test_parts_cut_where_the_gait_changes_do_not_reach_across_the_change():
    """The step across a gait change is a blend of both gaits: the parts beside it stay at their landings even
    where the legs repeat alike on both sides (two runs of one tempo from two takes), so no loop holds it."""
    from mocycle.activities import Activity, _reach

    walk = synthetic_walk(n_frames=600, fps=60.0, period_s=1.0, noise_deg=0.5, seed=2).motion

    def parts():
        return [Activity(start=60, stop=300, kind="walk straight", period_frames=60.0),
                Activity(start=330, stop=540, kind="walk straight", period_frames=60.0)]

    free = parts()
    _reach(walk, free, walk.n_frames)
    assert free[0].stop > 300 or free[1].start < 330  # alike legs: without a change the parts grow over the step
    held = parts()
    _reach(walk, held, walk.n_frames, changes={300, 330})
    assert (held[0].stop, held[1].start) == (300, 330)
    assert held[0].start < 60 and held[1].stop > 540  # their other ends still reach


def test_a_quick_wave_beside_a_slow_one_is_looped_at_its_own_period_not_twice_it():
    """A motion repeats at twice its period too: where a slow wave sets the period of the stretch, the quick wave
    before it must still be looped at its own period."""
    from mocycle.datasets import join_takes

    fps = 30.0
    takes = [synthetic_wave(n_frames=int(6 * fps), fps=fps, hand="right", wave_period_s=0.6, seed=4).motion,
             synthetic_wave(n_frames=int(8 * fps), fps=fps, hand="right", wave_period_s=1.3, seed=5).motion]
    s = join_takes(takes, ["wave", "wave"])
    loops = segment_activities(s.motion).loopable()
    assert len(loops) == 2
    assert [round(p.period_frames / fps, 1) for p in loops] == [0.6, 1.3], [(p.start, p.stop, p.period_frames)
                                                                          for p in loops]


def _stooped(motion, degrees: float):
    """``motion`` with the spine, neck and forearms bent ``degrees`` more about their x axis at every frame: the
    same steps, tempo and speed, another posture (another take of the same walk)."""
    from scipy.spatial.transform import Rotation

    q = motion.rotations.copy()
    for name in ("Spine", "Spine1", "Neck", "LeftForeArm", "RightForeArm"):
        j = motion.skeleton.index(name)
        q[:, j] = (Rotation.from_quat(q[:, j]) * Rotation.from_euler("x", degrees, degrees=True)).as_quat()
    return motion.replace(rotations=q)


@pytest.mark.parametrize("seed", [1, 2])
def test_two_takes_of_one_walk_in_another_posture_are_two_parts(seed):
    """Two takes of a walk at one tempo and speed, whose landings run on through the join, differ in posture
    only: the gait changes there (the strides' mean poses), and no loop holds more than half a stride of the
    other take.  The same walk without the change of posture stays one part."""
    from mocycle.datasets import join_takes

    fps = 60.0
    walk = synthetic_walk(n_frames=int(12 * fps), fps=fps, period_s=1.0, noise_deg=0.5, seed=seed).motion
    same = join_takes([walk[:370], walk[360:]], ["walk", "walk"])
    assert [(p.kind, p.start, p.stop) for p in segment_activities(same.motion).loopable()] == \
        [("walk straight", 0, same.motion.n_frames)]
    s = join_takes([walk[:370], _stooped(walk, 20.0)[360:]], ["walk", "walk"])
    border = s.stretches[0][2]
    loops = segment_activities(s.motion).loopable()
    assert len(loops) == 2, [(p.kind, p.start, p.stop) for p in loops]
    assert loops[0].stop - border <= 0.5 * loops[0].period_frames
    assert border - loops[1].start <= 0.5 * loops[1].period_frames


def test_return_distance_stays_a_number_where_a_period_is_over_half_the_frames():
    """Frames with no pose a period away on either side cannot be seen to come back; the others still can (a
    stretch of 1.5 periods whose feet step in time needs them: it was all NaN, never alike)."""
    from mocycle.activities import ALIKE, _return_distance

    t = np.arange(60, dtype=np.float64)
    X = np.column_stack([np.sin(2 * np.pi * t / 40), np.cos(2 * np.pi * t / 40)])
    d = _return_distance(X, 40.0, 5)
    assert np.all(np.isfinite(d))
    assert np.all(d[:15] < ALIKE) and np.all(d[45:] < ALIKE)  # a period apart: the same pose
    assert np.all(d[25:35] > ALIKE)  # nothing a period away


def test_a_short_gait_part_is_judged_on_its_own_frames_not_on_the_takes_beside_it():
    """A walk of 1.7 strides between two waves: its own frames compare more than a step and are alike, so it is a
    gait part; the frames beside it (another take in a session) are not looked at (they were: unlike, the walk
    was dropped)."""
    from mocycle.activities import Activity, _legs_repeat_in
    from mocycle.datasets import join_takes

    fps = 60.0
    takes = [synthetic_wave(n_frames=180, fps=fps, seed=1).motion,
             synthetic_walk(n_frames=120, fps=fps, period_s=1.0, noise_deg=0.5, seed=2).motion,
             synthetic_wave(n_frames=180, fps=fps, seed=3).motion]
    s = join_takes(takes, ["wave", "walk", "wave"])
    _, a, b = s.stretches[1]
    walk = Activity(start=a + 3, stop=b - 3, kind="walk straight", period_frames=60.0)
    assert _legs_repeat_in(s.motion, walk)
    waves = Activity(start=0, stop=a - 3, kind="walk straight", period_frames=60.0)
    assert not _legs_repeat_in(s.motion, waves)  # legs that stand still while the arms wave make no gait


@pytest.mark.parametrize("n_walk,first", [(150, 32), (140, 27)])
def test_a_short_gait_part_inside_its_take_is_judged_a_step_beyond_it_before_a_stride(n_walk, first):
    """A walk take between two waves whose landings give a part of 1.4 strides starting half a stride into the
    take (its first landing lost at the join): a step on either side of the part is still the walk, and its legs
    are alike a stride later there; a stride on either side takes in the waves (legs that stand), and the walk
    was dropped as no gait."""
    from mocycle.activities import Activity, _legs_repeat_in
    from mocycle.datasets import join_takes

    fps = 60.0
    for seed in (1, 2, 3):
        takes = [synthetic_wave(n_frames=180, fps=fps, seed=seed).motion,
                 synthetic_walk(n_frames=n_walk, fps=fps, period_s=1.0, noise_deg=0.5, seed=seed + 1).motion,
                 synthetic_wave(n_frames=180, fps=fps, seed=seed + 2).motion]
        s = join_takes(takes, ["wave", "walk", "wave"])
        _, a, b = s.stretches[1]
        walk = Activity(start=a + first, stop=a + first + 86, kind="walk straight", period_frames=60.0)
        assert _legs_repeat_in(s.motion, walk), seed


def _figures(n: int, period: float = 60.0, speed: float = 1.0, double: float = 0.3) -> np.ndarray:
    """Stride figures (:func:`mocycle.activities._stride_figures`' columns) of ``n`` steady straight strides."""
    return np.tile([period, 0.0, speed, 0.0, double], (n, 1)).astype(np.float64)


def test_a_blended_stride_at_a_chains_end_is_left_out_and_its_own_part_keeps_three():
    """Where one take meets the next the landings may run on into it for a step or two: the stride over the join
    (slower, with less double support) is left out, a step at a time; one that turns (a turn slows a walk) is
    kept, and so are the strides of a short part beyond a gait change (compared within its own part only)."""
    from mocycle.activities import _steady_ends

    strides = _figures(8)
    assert _steady_ends(strides, None) == (0, 8)
    strides[-1, 2:] = [0.6, 0.0, 0.1]  # the last stride runs into a slower take
    assert _steady_ends(strides, None) == (0, 7)
    strides[0, 0] = 80.0  # and the first one into the take before
    assert _steady_ends(strides, None) == (1, 7)
    turning = strides.copy()
    turning[-1, 1] = 40.0
    assert _steady_ends(turning, None) == (1, 8)
    # a gait change at landing 5: the last part holds strides 6 and 7 only, too few to judge one of them by
    assert _steady_ends(strides, None, cuts={5}) == (1, 8)
    poses = np.zeros((8, 3))
    poses[-1] = [0.0, 1.0, 0.0]  # the same figures, another posture: a blend as well
    assert _steady_ends(_figures(8), poses) == (0, 7)


def test_a_small_change_that_leaves_a_side_too_short_to_loop_is_no_cut():
    """A run of five strides that speeds up by a quarter after its third (a short take's wobble: its strides
    at 30 fps vary that much) was cut in two, a stride and a half and a stride, and neither piece looped: the
    take got no loop.  A change that small is cut only where both sides keep a stride and a half; a clear one
    (period and speed both jump, as where one take meets the next) is cut however short its sides."""
    from mocycle.activities import CLEAR_CHANGE, _change_scores, _gait_changes

    def strides(*runs):
        return np.vstack([_figures(n, period=period, speed=speed) for n, period, speed in runs])

    small = strides((3, 60.0, 1.0), (2, 60.0, 1.25))
    assert 0 < _change_scores(small, None).max() < CLEAR_CHANGE
    assert _gait_changes(small) == set()
    assert _gait_changes(strides((2, 60.0, 1.0), (3, 60.0, 1.25))) == set()
    assert _gait_changes(strides((3, 60.0, 1.0), (3, 60.0, 1.25))) == {3}  # four landings a side: cut
    assert _gait_changes(strides((8, 60.0, 1.0), (8, 60.0, 1.25))) == {7}
    clear = strides((3, 60.0, 1.0), (2, 75.0, 1.5))
    assert _change_scores(clear, None).max() >= CLEAR_CHANGE
    assert _gait_changes(clear) == {3}


def test_a_gait_change_is_cut_once_at_the_step_that_blends_the_two_takes():
    """Where one take meets the next, the step across the join spoils the two strides that hold it (41 and 39
    frames between walks of 36 and 31).  The change scores (medians of three strides a side) stay high over
    four landings and peak two landings past that step; the cut searched only one landing about the peak
    dropped a step of either take instead, and the strides left between the two cuts (the blend) were looked at
    again as one motion: a walk loop across the join.  The steadiest cut from three landings before the peak to two
    after it drops the blended step itself, once."""
    from mocycle.activities import _change_scores, _gait_changes

    strides = np.vstack([_figures(8, period=36.0), _figures(1, period=41.0), _figures(1, period=39.0),
                         _figures(8, period=31.0, speed=1.2)])
    score = _change_scores(strides, None)
    assert 3 + int(np.argmax(score)) == 11  # the peak: two landings after the blended step (landings 9 to 10)
    assert _gait_changes(strides) == {9}


def test_parts_found_between_gait_parts_keep_their_landings_in_the_takes_frames():
    """A stretch between gait parts is looked at on its own frames; a walk found there by its feet (a chain of
    landings that broke) listed its landings counted from the stretch's first frame, not the take's."""
    from mocycle.activities import _Gap, _gap_parts, _steps_in, find_landings

    walk = synthetic_walk(n_frames=600, fps=60.0, period_s=1.0, noise_deg=0.5, seed=3).motion
    a, b = 200, 450
    gap = _Gap(walk[a:b], a, 1.2, True, {"joints": None, "step": 1}, _steps_in(find_landings(walk), a, b))
    stepping = [q for q in _gap_parts(gap) if q.landings]
    assert stepping and stepping[0].in_step
    for q in stepping:
        frames = [f for v in q.landings.values() for f in v]
        assert min(frames) >= q.start >= a and max(frames) < q.stop, (q.start, q.stop, q.landings)


def test_the_second_look_stays_on_one_side_of_a_gait_change():
    """Frames where steps were seen but nothing loops are looked at again without gait; where the gait was seen
    to change between two such parts, each side is looked at on its own (one look across both found a
    "periodic" motion holding the end of one take and the start of the next)."""
    from mocycle.activities import Activity, _second_look, find_landings

    walk = synthetic_walk(n_frames=360, fps=60.0, period_s=1.0, noise_deg=0.5, seed=3).motion
    landings = find_landings(walk)

    def looked(changes):
        seen = []

        def record(fn, gaps):
            seen.extend((g.offset, g.offset + g.motion.n_frames) for g in gaps)
            return [[] for _ in gaps]

        parts = [Activity(start=0, stop=150, kind="transition", landings={"left": [30]}),
                 Activity(start=150, stop=360, kind="transition", landings={"left": [200]})]
        _second_look(walk, parts, landings, 1.2, {"joints": None, "step": 1}, record, changes)
        return seen

    assert looked(()) == [(0, 360)]
    assert looked({150}) == [(0, 150), (150, 360)]


def test_a_run_whose_landings_run_on_into_the_walk_after_it_is_not_looped_across_the_join():
    """Joined end to end, a run's chain of landings runs on a step into the walk after it (the blend of the two
    keeps the tempo for a step): the steps about the join are a transition, the run's loop stays in the run
    (it held 39 frames of the walk, most of a run's stride) and the walk still loops."""
    from mocycle.datasets import join_takes

    fps = 60.0
    s = join_takes([synthetic_run(n_frames=254, fps=fps, period_s=0.7, noise_deg=0.5, seed=2).motion,
                    synthetic_walk(n_frames=240, fps=fps, period_s=1.1, noise_deg=0.5, seed=12).motion],
                   ["run", "walk"])
    border = s.stretches[0][2]
    parts = segment_activities(s.motion).parts
    loops = [p for p in parts if p.loop]
    assert [p.kind for p in loops] == ["run straight", "walk straight"], [(p.kind, p.start, p.stop) for p in parts]
    run, walk = loops
    assert run.stop - border <= 0.5 * run.period_frames and border - walk.start <= 0.5 * walk.period_frames
    assert any(p.kind == "transition" and p.start < border < p.stop for p in parts)


def test_a_run_joined_at_a_higher_floor_is_a_run_of_its_own():
    """A session's take whose floor stands 3 % of the body height above its neighbours' (takes captured or
    scaled apart): from the floor of the frames about them its stances never land, and the run was looped as a
    `periodic` motion; measured from their own level where no gait is found, they land, make a run part at its
    stride, and its chain stops where the walk's landings, on the other floor, begin (no loop over the border)."""
    from mocycle.axes import vertical_axis
    from mocycle.contacts import body_height, up_axis
    from mocycle.datasets import join_takes

    fps = 60.0
    walk = synthetic_walk(n_frames=240, fps=fps, period_s=1.0, seed=1).motion
    run = synthetic_run(n_frames=130, fps=fps, period_s=0.7, seed=2).motion
    up, j = vertical_axis(run), run.travel_joint
    lift = up * 0.03 * body_height(run, up_axis(run))
    run = run.replace(tracks={j: run.joint_translations(j) + lift})
    s = join_takes([walk, run, walk], ["walk", "run", "walk"])
    (_, a, b) = s.stretches[1]
    loops = segment_activities(s.motion).loopable()
    runs = [p for p in loops if p.kind.startswith("run")]
    assert len(runs) == 1, [(p.kind, p.start, p.stop) for p in loops]
    assert runs[0].period_frames == pytest.approx(0.7 * fps, rel=0.08)
    assert runs[0].start >= a - 5 and runs[0].stop <= b + 5  # within its take (the cross-fade is 10 frames)
    assert [p.kind for p in loops] == ["walk straight", "run straight", "walk straight"]


def _stepping_heights(levels_l, levels_r, step: int = 30, swing: int = 18, peak: float = 0.15) -> np.ndarray:
    """Heights ``(T, 2)`` (body heights over the floor) of a left and a right foot that step in turn, ``step``
    frames apart, each stance flat at its own level (``levels_*``: one per stance), each swing an arc of
    ``swing`` frames ``peak`` high: one contact joint per foot."""
    n = len(levels_l) + len(levels_r)
    T = (n + 1) * step
    h = np.zeros((T, 2))
    for foot, levels in ((0, levels_l), (1, levels_r)):
        starts = np.arange(foot * step, T, 2 * step)[: len(levels) + 1]
        for k, level in enumerate(levels):
            a = int(starts[k])
            b = min(T, a + 2 * step)
            h[a:b, foot] = level
            s = max(0, a - swing)  # the swing that lands at frame a, from the last stance's level
            before = levels[k - 1] if k > 0 else level
            arc = np.sin(np.linspace(0, np.pi, a - s, endpoint=False)) * peak
            h[s:a, foot] = np.linspace(before, level, a - s) + arc
    return h


@pytest.mark.parametrize("high_l,high_r,n", [((2,), (3,), 6), ((4,), (), 8), ((2, 5), (4,), 8)])
def test_stances_that_drift_from_step_to_step_still_make_one_chain_of_landings(high_l, high_r, n):
    """A walk whose stances stand at levels that drift from step to step by more than a landing's height (a
    retargeted rig's ankles, a floor that is not flat; ``high_*``: the stances 2.5 landing heights up): over the
    floor (the lowest level about), the higher stances land too high and the landings break into chains of a few
    steps; over each stance's own level they make one chain, longer than every piece of the floor's, which is
    kept (the iClone walks 07_02 and 07_06 in a session: no loop before)."""
    from mocycle.activities import LAND_HEIGHT, _gait_chains, _landings_from, _landings_of

    fps = 60.0
    levels_l = [2.5 * LAND_HEIGHT if k in high_l else 0.0 for k in range(n)]
    levels_r = [2.5 * LAND_HEIGHT if k in high_r else 0.0 for k in range(n)]
    h = _stepping_heights(levels_l, levels_r)
    sides = ("left", "right")
    pieces = [c.size for c in _gait_chains(_landings_of(h, [1, 1], sides), fps, least=3)]
    assert len(pieces) >= 2 and max(pieces) < 2 * n - 1  # broken over the floor
    found = _landings_from(h, [1, 1], sides, fps)
    chains = _gait_chains(found, fps, least=3)
    assert len(chains) == 1 and chains[0].size == 2 * n - 1
    assert np.all(np.abs(np.diff(found.frames[chains[0]]) - 30) <= 2)


def test_a_steady_chain_over_the_floor_is_kept_where_the_stances_own_levels_break_it():
    """Flat stances: the landings over the floor make one long chain and are kept as they are (none measured from
    the stances' own levels)."""
    from mocycle.activities import _gait_chains, _landings_from

    h = _stepping_heights([0.0] * 6, [0.0] * 6)
    found = _landings_from(h, [1, 1], ("left", "right"), 60.0)
    assert not found.own.any() if found.own is not None else True
    assert max(c.size for c in _gait_chains(found, 60.0, least=3)) >= 11


def test_a_one_frame_gap_between_parts_says_one_frame():
    """The reason of a gap too short to look at counts its frames in plain words ("only 1 frame", not "1
    frames")."""
    from mocycle.activities import _other

    walk = synthetic_walk(n_frames=120, fps=60.0, period_s=1.0, noise_deg=0.5, seed=3).motion
    one, = _other(walk, 10, 11, 1.2, True, {"joints": None, "step": 1})
    assert one.kind == "transition" and one.reason.startswith("only 1 frame (0.0 s) between activities")
    two, = _other(walk, 10, 12, 1.2, True, {"joints": None, "step": 1})
    assert two.reason.startswith("only 2 frames (")


def test_a_sliver_between_parts_is_merged_into_a_neighbour_that_does_not_loop():
    """A frame or two left between two cuts (a transition of one frame beside another transition) is merged
    into the part before it, or else the part after it, when that one does not loop; beside parts that loop
    on both sides it stays (a loop's frames are never grown by it)."""
    from mocycle.activities import Activity, _without_slivers

    def parts():
        return [Activity(start=0, stop=100, kind="walk straight", loop=True),
                Activity(start=100, stop=130, kind="transition", reason="steps where one take meets another",
                         landings={"left": [110]}),
                Activity(start=130, stop=132, kind="transition", reason="only 2 frames", landings={"right": [131]}),
                Activity(start=132, stop=133, kind="transition", reason="only 1 frame"),
                Activity(start=133, stop=200, kind="run straight", loop=True),
                Activity(start=200, stop=201, kind="gesture", reason="only 1 frame"),
                Activity(start=201, stop=300, kind="walk straight", loop=True)]

    out = _without_slivers(parts(), fps=30.0)
    assert [(p.kind, p.start, p.stop) for p in out] == [
        ("walk straight", 0, 100), ("transition", 100, 133), ("run straight", 133, 200), ("gesture", 200, 201),
        ("walk straight", 201, 300)]
    assert out[1].reason == "steps where one take meets another" and out[1].landings == {"left": [110], "right": [131]}
    first = [Activity(start=0, stop=2, kind="transition", reason="only 2 frames"),  # a sliver first: merged
             Activity(start=2, stop=40, kind="gesture", reason="once"),               # into the part after it
             Activity(start=40, stop=90, kind="run straight", loop=True)]
    out = _without_slivers(first, fps=30.0)
    assert [(p.kind, p.start, p.stop, p.reason) for p in out] == [("gesture", 0, 40, "once"),
                                                                   ("run straight", 40, 90, "")]


def _strides(periods, turns, speed=120.0):
    """Stride figures (:func:`mocycle.activities._stride_figures`' columns) of a walk: ``periods`` and ``turns``
    per stride, a steady speed, double support 0.4."""
    return np.array([(p, t, speed, 0.0, 0.4) for p, t in zip(periods, turns, strict=True)], dtype=np.float64)


def test_a_join_next_to_a_turn_is_cut_where_its_blended_strides_end():
    """One take walks out of a turn and the next, a walk of the same tempo, starts a stride and a half later:
    the change test needs two straight strides before the join and has one, so the strides next to the turn are
    held against the steady ones beyond them; the part after starts where the last blended stride ends (the
    youthful session in the issue's order: turn, then walk, looped as one walk across the join before)."""
    from mocycle.activities import _joins_at_turns

    turns = [0, 0, 20, 65, 70, 22, 1, 6, 5, 0, 0, 0, 0, 0]
    periods = [32, 34, 34, 34, 31, 31, 31, 35, 35, 31, 31, 32, 32, 31]  # strides 7-8 blend the join
    assert _joins_at_turns(_strides(periods, turns), None) == {9}  # landings 9 on: the walk take's
    steady = [32, 34, 34, 34, 31, 31, 31, 31, 32, 31, 31, 32, 32, 31]
    assert _joins_at_turns(_strides(steady, turns), None) == set()  # one take walking on: no cut
    one = [32, 34, 34, 34, 31, 31, 31, 35, 32, 31, 31, 32, 32, 31]  # one stride off: the part after starts at its end
    assert _joins_at_turns(_strides(one, turns), None) == {8}
    # the mirror: a walk joined to a take that walks into a turn; the part before ends where the blend starts
    back = list(reversed(periods))
    assert _joins_at_turns(_strides(back, list(reversed(turns))), None) == {len(periods) - 9}
    # a cut already made among the strides held against, or too few straight strides beyond: not looked at
    assert _joins_at_turns(_strides(periods, turns), None, cuts={11}) == set()
    assert _joins_at_turns(_strides(periods[:11], turns[:11]), None) == set()


def test_the_issues_session_order_gives_no_loop_across_the_last_turns_join(shared_data):
    """The sessions issue's order (walk, turn, run, wave, gesture, turn, walk) from one performer's Bandai takes at
    30 fps: the last turn take walks out of its turn for a stride and a half and the walk after it keeps the tempo;
    no looped part reaches more than half a stride across a join into another take."""
    from mocycle.datasets import join_takes

    names = ["walk_youthful_025", "walk-turn-right_youthful_027", "run_youthful_019", "wave-both-hands_youthful_026",
             "raise-up-right-hand_youthful_023", "walk-turn-left_youthful_001", "walk_youthful_025"]
    paths = [shared_data / "bandai2" / f"dataset-2_{n}.bvh" for n in names]
    if not all(p.is_file() for p in paths):
        pytest.skip("the Bandai youthful takes are absent from ../shared/data/bandai2")
    labels = ["walk", "turn", "run", "wave", "gesture", "turn", "walk"]
    session = join_takes([read(p) for p in paths], labels)
    acts = segment_activities(session.motion)
    loops = [p for p in acts.parts if p.loop]
    assert len(loops) >= 7
    for p in loops:
        inside = [min(p.stop, b) - max(p.start, a) for _, a, b in session.stretches]
        assert sorted(inside)[-2] <= p.period_frames / 2, (p.kind, p.start, p.stop, session.stretches)
    last_walk = session.stretches[-1]
    assert any(p.start >= last_walk[1] - 16 and p.kind == "walk straight" for p in loops)


def _chain_figures(motion):
    """The one gait chain of ``motion``: its landing frames and stride figures."""
    from mocycle.activities import (
        _gait_chains,
        _horizontal_path,
        _stride_figures,
        find_landings,
        heading_degrees,
    )

    landings = find_landings(motion)
    chains = _gait_chains(landings, motion.fps, least=2)
    assert len(chains) == 1
    frames = landings.frames[chains[0]]
    return frames, _stride_figures(chains[0], landings, heading_degrees(motion), _horizontal_path(motion),
                                   motion.fps)


def test_a_join_of_one_gait_at_another_phase_is_a_phase_break():
    """Two takes of one walk joined at another phase keep the landings' rhythm but not the legs' repeat across
    the join: the break lies in the step that holds the join; joined at the same phase (or one take) there is
    none."""
    from mocycle.activities import _phase_breaks
    from mocycle.datasets import join_takes

    walk = synthetic_walk(n_frames=400, fps=30, period_s=1.0, noise_deg=1.0, seed=1).motion
    for offset, broken in ((0, False), (22, True)):
        session = join_takes([walk[60:340], walk[60 + offset:340]], ["walk", "walk"])
        frames, strides = _chain_figures(session.motion)
        join = session.stretches[0][2]
        breaks = _phase_breaks(session.motion, frames, strides)
        if broken:
            assert len(breaks) == 1
            c = breaks.pop()
            assert frames[c] <= join < frames[c + 1], (frames.tolist(), c, join)
        else:
            assert breaks == set()
    frames, strides = _chain_figures(walk[60:340])
    assert _phase_breaks(walk[60:340], frames, strides) == set()
    # a cut already made near the join: not looked at again
    session = join_takes([walk[60:340], walk[82:340]], ["walk", "walk"])
    frames, strides = _chain_figures(session.motion)
    c = int(np.searchsorted(frames, session.stretches[0][2])) - 1
    assert _phase_breaks(session.motion, frames, strides, cuts={c + 1}) == set()


def test_two_takes_of_one_walk_joined_at_another_phase_loop_apart(shared_data):
    """A Bandai walk joined to itself 15 frames on (one performer, one tempo and posture, another phase: the
    strides show no change, the legs' repeat breaks at the join): no looped part reaches more than half a stride
    across the join (one loop across both before)."""
    from mocycle.datasets import join_takes

    path = shared_data / "bandai" / "dataset-1_walk_tired_001.bvh"
    if not path.is_file():
        pytest.skip("dataset-1_walk_tired_001.bvh is absent from ../shared/data/bandai")
    take = read(path)
    session = join_takes([take, take[15:]], ["walk", "walk"])
    loops = [p for p in segment_activities(session.motion).parts if p.loop]
    assert len(loops) >= 2
    for p in loops:
        inside = [min(p.stop, b) - max(p.start, a) for _, a, b in session.stretches]
        assert sorted(inside)[-2] <= p.period_frames / 2, (p.kind, p.start, p.stop, session.stretches)


@pytest.mark.parametrize("make", [synthetic_walk, synthetic_run])
@pytest.mark.parametrize("off", [1.1, 1.2])
def test_a_short_gait_part_repeats_at_its_legs_stride_when_its_landings_put_it_off(make, off):
    """A part of 1.7 strides whose few landings make the stride 10-20 % long (the floating feet of a retargeted
    rig, measured from their stances' own levels: an iClone jog's 50 frames where its legs repeat at 45) is still
    a gait: its legs repeat a stride later by their own stride (legs_check then gives the part that period)."""
    from mocycle.activities import Activity, _legs_repeat_in

    take = make(fps=60, seed=3)
    period = float(np.nanmedian(take.period_frames))
    motion = take.motion[:int(1.7 * period)]
    part = Activity(start=0, stop=motion.n_frames, kind="run", limbs="legs", period_frames=off * period)
    assert _legs_repeat_in(motion, part)


def test_a_short_part_whose_legs_do_not_repeat_is_no_gait():
    """Most of a walk's stride joined to most of a run's: at no lag do the legs repeat."""
    from mocycle.activities import Activity, _legs_repeat_in
    from mocycle.datasets import join_takes

    walk, run = synthetic_walk(fps=60, seed=3), synthetic_run(fps=60, seed=3)
    period = float(np.nanmedian(walk.period_frames))
    motion = join_takes([walk.motion[:int(0.9 * period)], run.motion[:int(0.9 * period)]], ["walk", "run"],
                        crossfade=6).motion
    for off in (1.0, 1.1):
        part = Activity(start=0, stop=motion.n_frames, kind="walk", limbs="legs", period_frames=off * period)
        assert not _legs_repeat_in(motion, part)


def test_a_gait_found_by_the_cohomology_takes_its_legs_period_where_they_overrule():
    """A walk whose chain of landings broke is found by the cohomology (_stepping_part); over a cycle and a half
    its period came out 2-6 % short of the legs' own.  The legs check it as they check a gait part's."""
    from mocycle.activities import _stepping_part, find_landings, line_periodic

    take = synthetic_walk(fps=60, seed=3)
    period = float(np.nanmedian(take.period_frames))
    motion = take.motion[:int(1.6 * period)]
    steps = find_landings(motion)
    n = motion.n_frames
    for said, want in ((0.94 * period, period), (period, period)):
        pm = line_periodic(np.arange(n) / said, said, motion.frame_time, "cohomology", "all", "")
        part = _stepping_part(motion, 0, n, pm, steps, "periodic")
        assert abs(part.period_frames / want - 1) < 0.01
        assert part.periodic.period_frames == part.period_frames
        assert abs(part.periodic.unwrapped[-1] - part.periodic.unwrapped[0] - (n - 1) / part.period_frames) < 1e-9
    assert part.periodic.period_source == "cohomology"  # the legs agree: the cohomology's phase is kept


def test_a_take_played_again_and_again_is_no_motion_that_repeats():
    """A session that plays one non-periodic take (smooth random motion, a wandering walk) five times in a row
    repeats every 9.7 s, and the cohomology sees that circle; a sequence done again is no cyclic motion to loop
    (:data:`MAX_REPEAT_S`): no part repeats more slowly than that, none is looped at the take's length."""
    from mocycle.activities import MAX_REPEAT_S, segment_activities
    from mocycle.datasets import join_takes, synthetic_nonperiodic

    fps = 30.0
    take = synthetic_nonperiodic(n_frames=300, fps=fps, seed=2).motion
    session = join_takes([take] * 5, ["take"] * 5).motion
    parts = segment_activities(session).parts
    periods = [p.period_frames for p in parts if np.isfinite(p.period_frames)]
    assert all(P <= MAX_REPEAT_S * fps for P in periods), [(p.kind, p.start, p.stop, p.period_frames) for p in parts]
    assert not any(p.loop and p.period_frames > 0.5 * take.n_frames for p in parts)
