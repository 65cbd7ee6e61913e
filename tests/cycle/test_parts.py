"""Parts are the only route (issue 35): a capture session in, every steady part out as a loop of its own.

Every take here is generated: sessions are joined from synthetic takes (:func:`mocycle.datasets.join_takes`),
whose labels are the truth of each stretch.  The loops are judged against that truth and against the motion
(the heading from the hips, the feet's heights), not against the figures the code prints.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from mocycle.activities import MIN_REPEATS, gait_of, segment_activities
from mocycle.cli import app
from mocycle.datasets import (
    join_takes,
    synthetic_gesture,
    synthetic_run,
    synthetic_sway,
    synthetic_walk,
    synthetic_walk_turn_walk,
    synthetic_wave,
)
from mocycle.io import read, write

runner = CliRunner()
FPS = 30.0


def _session(tmp_path, takes, name="session"):
    s = join_takes([t.motion for _, t in takes], [label for label, _ in takes])
    return write(s.motion, tmp_path / f"{name}.bvh"), s


def _loop(path, tmp_path, *extra):
    result = runner.invoke(app, ["loop", str(path), "-o", str(tmp_path / "out.bvh"), "--part", "all", "--root",
                                 "motion", "--json", *extra])
    return result, (json.loads(result.stdout) if result.stdout.strip() else None)


def _stretch_of(loop, stretches) -> tuple[int, int]:
    """The stretch holding most of a loop's frames, and how many of its frames lie in other stretches."""
    a, b = loop["frames"]
    overlap = [max(0, min(b, e) - max(a, s)) for _, s, e in stretches]
    k = int(np.argmax(overlap))
    return k, sum(overlap) - overlap[k]


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """walk, dance step on the spot (legs moving, no landings), wave, run, raised right hand, walk."""
    tmp = tmp_path_factory.mktemp("mixed")
    takes = [("walk", synthetic_walk(n_frames=150, fps=FPS, period_s=1.0, noise_deg=1.0, seed=1)),
             ("sway", synthetic_sway(n_frames=150, fps=FPS, period_s=1.2, seed=2)),
             ("wave", synthetic_wave(n_frames=150, fps=FPS, hand="right", wave_period_s=0.6, seed=3)),
             ("run", synthetic_run(n_frames=120, fps=FPS, period_s=0.7, noise_deg=1.0, seed=4)),
             ("raise", synthetic_gesture(n_frames=90, fps=FPS, hand="right", seed=5)),
             ("walk", synthetic_walk(n_frames=150, fps=FPS, period_s=1.2, noise_deg=1.0, seed=6))]
    path, s = _session(tmp, takes)
    result, facts = _loop(path, tmp)
    return tmp, path, s, result, facts


def test_every_stretch_of_a_session_gets_a_loop_of_its_own(mixed):
    tmp, path, s, result, facts = mixed
    assert result.exit_code == 0, result.output
    assert facts["status"] == "ok" and "Traceback" not in result.output
    owners = {}
    for loop in facts["loops"]:
        k, bleed = _stretch_of(loop, s.stretches)
        assert bleed <= 0.5 * loop["period_frames"], (loop["kind"], loop["frames"], s.stretches)  # no border spanned
        owners.setdefault(s.stretches[k][0], []).append(loop["kind"])
        assert read(loop["output"]).n_frames == loop["cycle_frames"]
    assert set(owners) == {"walk", "sway", "wave", "run"}, owners   # the raised hand is never looped
    assert "periodic" in owners["sway"] and "arms" in owners["wave"] and "run straight" in owners["run"]
    # every part that loops is looped or listed with its reason
    done = {loop["part"] for loop in facts["loops"]} | {d["part"] for d in facts["not_looped"]}
    assert done == set(range(len(facts["parts"])))


def test_phase_lists_the_parts_loop_loops(mixed):
    tmp, path, s, _, facts = mixed
    result = runner.invoke(app, ["phase", str(path), "--json"])
    assert result.exit_code == 0, result.output
    phase = json.loads(result.stdout)
    assert phase["parts"] == facts["parts"]
    assert [(c["part"], c["kind"]) for c in phase["classes"]] == \
        [(k, p["kind"]) for k, p in enumerate(facts["parts"]) if p["loop"]]
    by_part = {loop["part"]: loop for loop in facts["loops"]}
    for c in phase["classes"]:
        if c["part"] in by_part:
            assert c["period_frames"] == pytest.approx(by_part[c["part"]]["period_frames"], rel=1e-6)


def test_part_k_is_always_the_kth_part(mixed):
    tmp, path, s, _, facts = mixed
    parts = facts["parts"]
    wave = next(k for k, p in enumerate(parts) if p["kind"] == "arms")
    result = runner.invoke(app, ["loop", str(path), "-o", str(tmp / "w.bvh"), "--part", str(wave), "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout)["part"] == wave
    gesture = next(k for k, p in enumerate(parts) if not p["loop"])
    result = runner.invoke(app, ["loop", str(path), "-o", str(tmp / "g.bvh"), "--part", str(gesture), "--json"])
    refused = json.loads(result.stdout)
    assert result.exit_code == 3 and f"part {gesture}" in refused["reason"] and "does not loop" in refused["reason"]
    assert not (tmp / "g.bvh").exists()
    result = runner.invoke(app, ["loop", str(path), "-o", str(tmp / "c.bvh"), "--class", str(wave), "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout)["part"] == wave and "deprecated" in result.stderr


def test_one_part_that_fails_does_not_sink_the_others(tmp_path):
    """A fit that cannot be made on a short part (more harmonics than its frames carry) is that part's
    reason; the walk beside it is looped and the exit is 0."""
    takes = [("walk", synthetic_walk(n_frames=300, fps=60.0, period_s=1.0, noise_deg=1.0, seed=1)),
             ("run", synthetic_run(n_frames=100, fps=60.0, period_s=0.7, noise_deg=1.0, seed=2))]
    path, s = _session(tmp_path, takes)
    result, facts = _loop(path, tmp_path, "--harmonics", "25")  # 25 fit a 60-frame walk, not a 42-frame run
    assert result.exit_code == 0, result.output
    assert [loop["kind"] for loop in facts["loops"]] == ["walk straight"]
    [run] = [d for d in facts["not_looped"] if d["kind"] == "run straight"]
    assert "needs velocities" in run["reason"] or "K must be" in run["reason"]
    # nothing loops: exit 3 with the JSON, never 1
    alone = write(takes[1][1].motion, tmp_path / "run.bvh")
    result, facts = _loop(alone, tmp_path, "--harmonics", "25")
    assert result.exit_code == 3 and facts["status"] == "no-periodic-motion" and facts["not_looped"]


def test_a_raised_hand_is_a_gesture_and_a_wave_is_a_wave_from_its_first_swing():
    raised = segment_activities(synthetic_gesture(n_frames=150, fps=FPS, hand="right", seed=3).motion)
    assert not raised.loopable()
    take = synthetic_wave(n_frames=240, fps=FPS, hand="left", wave_period_s=0.6, raise_s=0.5, seed=4)
    [wave] = segment_activities(take.motion).loopable()
    (_, a, b), period = [seg for seg in take.segments if seg[0] == "wave"][0], 0.6 * FPS
    assert wave.kind == "arms" and wave.start <= a + period and wave.stop >= b - period


def test_walk_and_run_are_told_by_their_feet():
    assert gait_of(flight=0.2, double=0.0, speed=0.5, body=1.0) == "run"      # a slow jog with flight
    assert gait_of(flight=0.0, double=0.27, speed=2.0, body=1.0) == "walk"    # a fast walk: double support
    assert gait_of(flight=0.0, double=0.05, speed=2.0, body=1.0) == "run"     # the feet cannot tell: speed
    assert gait_of(flight=0.3, double=0.2, speed=0.5, body=1.0) == "walk"     # feet that say both: speed
    assert gait_of(flight=0.11, double=0.08, speed=0.9, body=1.0) == "walk"   # floating feet (iClone walk): speed
    assert gait_of(flight=0.11, double=0.0, speed=0.9, body=1.0) == "run"     # flight and no double support at all
    fast = synthetic_walk(n_frames=240, fps=60.0, period_s=0.55, noise_deg=0.5, seed=5).motion
    assert {p.kind for p in segment_activities(fast).loopable()} == {"walk straight"}
    run = synthetic_run(n_frames=240, fps=60.0, period_s=0.9, noise_deg=0.5, seed=6).motion
    assert {p.kind for p in segment_activities(run).loopable()} == {"run straight"}


@pytest.mark.parametrize("turn, strides", [(90.0, 2.0), (-90.0, 1.5), (60.0, 2.0)])
def test_a_turn_of_two_strides_or_less_is_looped_and_holds_no_straight_walk(tmp_path, turn, strides):
    take = synthetic_walk_turn_walk(2.0, turn, strides, 2.0, fps=60.0, period_s=1.0, noise_deg=1.0, seed=7)
    src = write(take.motion, tmp_path / "wtw.bvh")
    result, facts = _loop(src, tmp_path)
    assert result.exit_code == 0, result.output
    turning = [loop for loop in facts["loops"] if "turning" in loop["kind"]]
    assert len(turning) == 1, [loop["kind"] for loop in facts["loops"]]
    a, b = turning[0]["frames"]
    rate = np.abs(np.gradient(take.heading_deg))
    P = turning[0]["period_frames"]
    straight = np.count_nonzero(rate[a:b] < 0.1 * rate.max())
    assert straight < 0.25 * P, (a, b, straight)   # no 3/4 of a stride straight inside a turning loop
    h = take.heading_deg
    assert turning[0]["turn_per_cycle_deg"] == pytest.approx((h[b - 1] - h[a]) / (b - 1 - a) * P,
                                                              abs=max(10.0, 0.25 * abs(turn) / strides))


def test_no_part_of_under_its_periods_loops_and_every_period_is_shorter_than_its_part():
    takes = [synthetic_walk(n_frames=70, fps=FPS, period_s=1.0, seed=1).motion,       # 2.3 strides
             synthetic_walk(n_frames=33, fps=FPS, period_s=1.0, seed=2).motion,       # 1.1 strides
             synthetic_wave(n_frames=60, fps=FPS, wave_period_s=0.6, raise_s=0.3, seed=3).motion,
             join_takes([synthetic_walk(n_frames=150, fps=FPS, seed=4).motion,
                         synthetic_sway(n_frames=60, fps=FPS, period_s=1.2, seed=5).motion,
                         synthetic_run(n_frames=150, fps=FPS, seed=6).motion], ["a", "b", "c"]).motion]
    for motion in takes:
        for p in segment_activities(motion, min_periods=1.2).parts:
            if p.loop:
                least = 1.2 if p.gait else MIN_REPEATS
                assert p.n_periods >= least and p.period_frames < p.n_frames and p.periodic is not None


def test_a_session_at_120_fps_is_cut_as_at_30(tmp_path):
    takes = [synthetic_walk(n_frames=150, fps=FPS, period_s=1.0, noise_deg=1.0, seed=1).motion,
             synthetic_walk_turn_walk(1.5, 90.0, 2.0, 1.5, fps=FPS, period_s=1.1, noise_deg=1.0, seed=2).motion,
             synthetic_run(n_frames=120, fps=FPS, period_s=0.7, noise_deg=1.0, seed=3).motion]
    s = join_takes(takes, ["walk", "turn", "run"])
    slow = [(p.kind, p.start, p.stop) for p in segment_activities(s.motion).loopable()]
    fast = [(p.kind, p.start / 4, p.stop / 4) for p in segment_activities(s.motion.resample(120.0)).loopable()]
    assert [k for k, *_ in slow] == [k for k, *_ in fast]
    for (_, a, b), (_, c, d) in zip(slow, fast, strict=True):
        assert abs(a - c) <= 4 and abs(b - d) <= 4


@pytest.mark.parametrize("closing", [True, False])
def test_a_clip_of_one_cycle_loops_at_its_own_length(tmp_path, closing):
    """A game clip is one cycle, often with a closing frame: looped as it is, exit 0, at its own length."""
    n = 60
    clip = synthetic_walk(n_frames=n + closing, fps=60.0, period_s=1.0, noise_deg=0.0, seed=3).motion
    src = write(clip, tmp_path / "clip.bvh")
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "out.bvh"), "--root", "motion", "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["cycle_frames"] == n and facts["method"] == "clip" and "one cycle" in facts["reason"]
    looped = read(tmp_path / "out.bvh")
    np.testing.assert_allclose(looped.rotations[:n], clip.rotations[:n], atol=1e-6)  # the clip as it is
    assert "only 1.00 periods" not in result.stderr


def test_one_cycle_clips_blend_transition_and_stretch(tmp_path):
    walk = write(synthetic_walk(n_frames=61, fps=60.0, period_s=1.0, noise_deg=0.3, seed=1).motion,
                 tmp_path / "walk.bvh")
    run = write(synthetic_run(n_frames=42, fps=60.0, period_s=0.7, noise_deg=0.3, seed=2).motion,
                tmp_path / "run.bvh")
    blend = runner.invoke(app, ["blend", str(walk), str(run), "-o", str(tmp_path / "b.bvh"), "--json"])
    assert blend.exit_code == 0, blend.output
    assert json.loads(blend.stdout)["input_periods_frames"] == [60.0, 42.0]
    tr = runner.invoke(app, ["transition", str(walk), str(run), "-o", str(tmp_path / "t.bvh")])
    assert tr.exit_code == 0, tr.output
    st = runner.invoke(app, ["stretch", str(walk), "--factor", "2.5", "-o", str(tmp_path / "s.bvh"), "--json"])
    assert st.exit_code == 0 and read(tmp_path / "s.bvh").n_frames == round(61 * 2.5), st.output


def test_a_gesture_that_ends_where_it_began_is_no_cycle():
    from mocycle.activities import one_cycle

    assert one_cycle(synthetic_gesture(n_frames=120, fps=60.0, seed=1).motion) is None
    assert one_cycle(synthetic_walk(n_frames=90, fps=60.0, noise_deg=0.0).motion) is None  # 1.5 cycles


@pytest.mark.parametrize("seconds", [2.0, 9.0])
def test_a_take_longer_than_the_longest_repeat_is_no_clip_of_one_cycle(seconds):
    """One stride of a walk lasting ``seconds`` is a clip of one cycle when it lasts no longer than a repeating
    motion may (:data:`~mocycle.activities.MAX_REPEAT_S`); a longer take is none, and is not searched for a repeat
    over lags up to its length (its length squared: minutes for a few minutes of capture where nothing loops)."""
    from mocycle.activities import MAX_REPEAT_S, one_cycle

    fps = 30.0
    n = int(round(seconds * fps))
    take = synthetic_walk(n_frames=n, fps=fps, period_s=seconds, noise_deg=0.0, seed=1).motion
    assert one_cycle(take) == (n if seconds <= MAX_REPEAT_S else None)
