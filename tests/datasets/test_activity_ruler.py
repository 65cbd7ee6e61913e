"""The issue-28 benchmark's ruler (benchmarks/activities.py) measures what the synthetic takes' truth says.

The benchmark judges the lead's loops with it, so it must read the stride period from the feet, the
arms' period of a wave, standing legs and the heading's turn on takes whose truth is exact.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from mocycle.datasets import (
    synthetic_gesture,
    synthetic_run,
    synthetic_walk,
    synthetic_walk_then_wave,
    synthetic_walk_turn_walk,
    synthetic_wave,
    to_z_up,
)

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "activities.py"


@pytest.fixture(scope="module")
def ruler():
    spec = importlib.util.spec_from_file_location("activities_ruler", _PATH)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod                  # dataclasses look their module up while defining
    try:
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.modules.pop(spec.name, None)


@pytest.mark.parametrize(("gen", "period_s", "fps"), [(synthetic_walk, 1.0, 60), (synthetic_walk, 1.2, 30),
                                                      (synthetic_run, 0.7, 30), (synthetic_run, 0.6, 60)])
def test_stride_period_from_the_feet(ruler, gen, period_s, fps):
    take = gen(n_frames=int(8 * fps), fps=fps, period_s=period_s, noise_deg=1.0, seed=4)
    body = ruler.Body.of(take.motion)
    assert body.names["up"] == "+Y" and body.names["feet"] == ["LeftToeBase", "RightToeBase"]
    period, how = body.stride_period(0, take.n_frames)
    assert how == "feet"
    assert period == pytest.approx(period_s * fps, rel=0.03)


def test_z_up_take_gives_the_same_ruler(ruler):
    take = synthetic_walk_turn_walk(turn_deg=-90, fps=30, period_s=1.1, noise_deg=1.0, seed=2)
    a, b = ruler.Body.of(take.motion), ruler.Body.of(to_z_up(take.motion))
    assert b.names["up"] == "+Z"
    assert b.stride_period(0, take.n_frames) == a.stride_period(0, take.n_frames)
    assert np.allclose(b.heading - b.heading[0], a.heading - a.heading[0], atol=1e-6)


@pytest.mark.parametrize(("turn", "strides"), [(90, 2), (-45, 3)])
def test_heading_turn_rate_and_turn_per_cycle(ruler, turn, strides):
    fps, period_s = 60, 1.0
    take = synthetic_walk_turn_walk(turn_deg=turn, turn_strides=strides, fps=fps, period_s=period_s,
                                    noise_deg=1.0, seed=1)
    body = ruler.Body.of(take.motion)
    (_, _, b), (_, _, c), _ = take.segments
    truth = np.polyfit(np.arange(b, c) / fps, take.heading_deg[b:c], 1)[0]
    assert body.turn_rate(b, c) == pytest.approx(truth, rel=0.1)
    assert abs(body.turn_rate(0, b)) < 1.0 and abs(body.turn_rate(c, take.n_frames)) < 1.0
    # the turn over a cycle inside a range: the truth's one-cycle heading change, pelvis swing cancelled
    for lo, hi in ((b - 30, c + 30), (0, b), (b + 10, b + 80)):
        want = np.mean(take.heading_deg[lo + 60:hi] - take.heading_deg[lo:hi - 60])
        assert body.turn_over(lo, hi, 60) == pytest.approx(want, abs=1.5)
    # the whole take mixes a straight and a turning part for the windows of one stride (90 deg only:
    # 45 deg in 3 strides turns 17 deg/s, under the 20 deg/s the ruler calls turning)
    w = body.window_rates(0, take.n_frames, period_s * fps)
    mixed = np.sum(np.abs(w) < ruler.STRAIGHT_RATE) >= 30 and np.sum(np.abs(w) > ruler.TURN_RATE) >= 30
    assert mixed == (abs(turn) == 90)


def test_turn_per_cycle_of_a_circle(ruler):
    from mocycle.datasets import synthetic_circle_walk
    take = synthetic_circle_walk(n_frames=240, fps=60, period_s=1.0, turn_per_cycle_deg=30.0, noise_deg=1.0)
    assert ruler.Body.of(take.motion).turn_per_cycle(60) == pytest.approx(30.0, abs=1.0)


@pytest.mark.parametrize(("hand", "period_s", "fps"), [("left", 0.6, 60), ("both", 0.5, 30)])
def test_wave_legs_stand_and_arms_give_the_period(ruler, hand, period_s, fps):
    take = synthetic_wave(n_frames=6 * fps, fps=fps, hand=hand, wave_period_s=period_s, noise_deg=0.5, seed=2)
    body = ruler.Body.of(take.motion)
    _, a, b = take.segments[1]
    assert body.stride_period(a, b)[1] == "legs standing"
    assert [len(body.landings(i)) for i in range(2)] == [0, 0]
    assert body.arms_period(a, b) == pytest.approx(period_s * fps, rel=0.03)


def test_walk_then_wave_and_gesture(ruler):
    take = synthetic_walk_then_wave(fps=60, noise_deg=0.5, seed=1)
    body = ruler.Body.of(take.motion)
    (_, w0, w1), (_, a, b) = take.steady_parts
    assert body.stride_period(w0, w1)[0] == pytest.approx(60.0, rel=0.05)
    assert body.stride_period(a, b)[1] == "legs standing"
    assert body.arms_period(a, b) == pytest.approx(36.0, rel=0.03)
    gesture = synthetic_gesture(240, 60, noise_deg=0.5, seed=0)
    assert ruler.Body.of(gesture.motion).stride_period(0, 240)[1] == "legs standing"


def test_reads_both_json_shapes(ruler):
    new = {"status": "ok", "reason": "", "loops": [
        {"frames": [120, 250], "kind": "walk turning left", "period_frames": 33.0, "turn_per_cycle_deg": 30.0,
         "output": "x.turning_left.bvh"}],
        "not_looped": [{"frames": [0, 120], "kind": "walk", "reason": "too short"}]}
    loops, not_looped, status, _ = ruler.read_loops(new, True)
    assert status == "ok" and not_looped[0]["kind"] == "walk"
    assert loops == [{"frames": (120, 250), "kind": "walk turning left", "period": 33.0, "turn": 30.0,
                      "output": "x.turning_left.bvh", "cycle_frames": None}]
    old = {"file": "f.bvh", "loops": [{"class": 1, "excitation": [[5, 90], [120, 300]], "period_frames": 60.0,
                                       "turn_per_cycle_deg": 1.0, "output": "o.class1.bvh", "cycle_frames": 60}]}
    loops, _, status, _ = ruler.read_loops(old, False)
    assert status == "ok" and loops[0]["frames"] == (5, 300) and loops[0]["kind"] == "class 1"
    flat = {"file": "f.bvh", "output": "o.bvh", "period_frames": 30.0, "excitation": [[0, 100]]}
    assert ruler.read_loops(flat, False)[0][0]["frames"] == (0, 100)
    assert ruler.read_loops(None, True) == ([], [], "", "")
