import pytest

from mocycle.datasets import synthetic_circle_walk, synthetic_walk
from mocycle.phase.gait import leg_curves, leg_sides, legs_period, sides_swap


@pytest.mark.parametrize("up", ["y", "z"])
def test_legs_split_into_left_and_right_on_any_up_axis(up):
    take = synthetic_circle_walk(n_frames=120, fps=30.0, turn_per_cycle_deg=60.0, up=up)
    legs, curves = leg_curves(take.motion)
    names = [take.motion.skeleton.names[j] for j in legs]
    a, b = leg_sides(curves)
    assert a.size >= 3
    for i, j in zip(a, b, strict=True):  # each pair is the same joint on both sides
        left, right = sorted([names[i], names[j]])
        assert left.startswith("Left") and right == left.replace("Left", "Right")
    # the up component is vertical: the feet hang well below the hips on either rig
    assert curves[:, [names.index("LeftFoot")], 1].mean() < -60


def test_legs_period_is_the_full_gait_cycle_and_sides_swap_across_a_step():
    take = synthetic_walk(n_frames=300, fps=30.0, period_s=1.0, noise_deg=1.0)
    _, curves = leg_curves(take.motion)
    assert abs(legs_period(take.motion, curves) - 30.0) < 0.6
    step, cycle = sides_swap(curves, 15.0), sides_swap(curves, 30.0)
    assert step.swaps and not cycle.swaps
    assert cycle.same < 0.1 * cycle.swapped
