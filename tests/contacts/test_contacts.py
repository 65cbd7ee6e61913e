import numpy as np
import pytest

from mocycle.contacts import detect_contacts, find_feet, largest_leg_step, lock_feet, ranges, skate
from mocycle.cycle import extract_cycle, lock_cycle
from mocycle.datasets import synthetic_still, synthetic_walk
from mocycle.motion import Motion


def test_ranges():
    assert ranges(np.array([0, 1, 1, 0, 1], bool)) == [(1, 3), (4, 5)]
    assert ranges(np.zeros(4, bool)) == []


def _planted_walk(n_frames=240, fps=60.0, **kw):
    """The synthetic walk (whose designed angles let the stance foot slide) with its root moved so that the
    lower ankle stands still horizontally: a walk whose feet are planted."""
    take = synthetic_walk(n_frames=n_frames, fps=fps, **kw)
    m = take.motion
    W = m.world_positions()
    feet = find_feet(m.skeleton)
    ankles = W[:, [f.ankle for f in feet]]                      # (T, 2, 3)
    low = np.argmin(ankles[:, :, 1], axis=1)
    step = np.diff(ankles, axis=0)[np.arange(m.n_frames - 1), low[:-1]]
    t = m.translations.copy()
    t[1:, 0, [0, 2]] -= np.cumsum(step[:, [0, 2]], axis=0)
    return take, Motion(m.skeleton, m.rotations, t, m.frame_time)


@pytest.mark.parametrize("fps", [30.0, 60.0, 120.0])
def test_each_foot_is_planted_for_a_stance_of_every_step_at_any_frame_rate(fps):
    _, walk = _planted_walk(n_frames=int(4 * fps), fps=fps)  # 4 steps per foot, 1 s period
    con = detect_contacts(walk)
    for f in range(2):
        rs = con.foot_ranges(f)
        inner = [r for r in rs if r[0] > 0 and r[1] < con.n_frames]
        assert len(inner) >= 3
        share = con.foot_mask(f).mean()
        assert 0.3 < share < 0.75, share   # a walk's stance is about 60 % of the cycle


def test_every_stance_is_found_on_a_drifting_floor(monkeypatch):
    """A take whose floor drifts up by 4 % of the body height (a drifting capture, a gentle slope): every
    stance is near its floor nearby (``local_floor``).  Measured from the lowest level of the whole take,
    the stances of the last third sit above the contact height and were missed."""
    from mocycle.contacts import body_height, detect

    fps = 60.0
    _, walk = _planted_walk(n_frames=int(8 * fps), fps=fps)   # 8 steps per foot
    up = np.array([0.0, 1.0, 0.0])
    t = walk.translations.copy()
    t[:, 0, 1] += np.linspace(0.0, 0.04 * body_height(walk, up), walk.n_frames)
    drifting = Motion(walk.skeleton, walk.rotations, t, walk.frame_time)

    def stances(con, f):
        return [r for r in con.foot_ranges(f) if r[0] > 0 and r[1] < con.n_frames]

    flat = detect_contacts(walk, up=up)
    con = detect_contacts(drifting, up=up)
    for f in range(2):
        assert len(stances(con, f)) == len(stances(flat, f)) >= 7
        assert con.foot_ranges(f)[-1][0] > 0.8 * con.n_frames      # the last steps too
    monkeypatch.setattr(detect, "FLOOR_SECONDS", 1e6)              # the whole take's lowest level
    whole = detect_contacts(drifting, up=up)
    assert all(not whole.foot_mask(f)[int(0.8 * whole.n_frames):].any() for f in range(2))


def _slid_walk():
    """The synthetic walk with a deliberate slide: the root surges back and forth by 6 cm at the step
    frequency, so a planted foot slides with it."""
    take, m = _planted_walk()
    t = m.translations.copy()
    t[:, 0, 2] += 6.0 * np.sin(2 * np.pi * 2 * take.unwrapped_phase)
    return Motion(m.skeleton, m.rotations, t, m.frame_time)


def test_locking_holds_the_feet_still_and_leaves_the_rest_alone():
    m = _slid_walk()
    con = detect_contacts(m)
    out = lock_feet(m, con)
    W0, W1 = m.world_positions(), out.world_positions()
    assert con.mask.any(axis=0).all()  # every contact joint is planted somewhere despite the slide
    for c, j in enumerate(con.joints):
        for s, e in ranges(con.mask[:, c]):
            assert np.abs(W1[s:e, j] - W1[s, j]).max() < 1e-6
    # bone lengths exact: every joint keeps its distance to its parent (the root's translation may change)
    par = m.skeleton.parents[1:]
    assert np.abs(np.linalg.norm(W1[:, 1:] - W1[:, par], axis=-1)
                  - np.linalg.norm(W0[:, 1:] - W0[:, par], axis=-1)).max() < 1e-9
    # outside a foot's contacts and their blend windows its leg is unchanged, where the root was not lowered
    n_blend = int(round(0.1 * m.fps))
    lowered = ~np.all(out.translations == m.translations, axis=(1, 2))
    checked = 0
    for f, foot in enumerate(con.feet):
        near = np.zeros(m.n_frames, bool)
        for s, e in con.foot_ranges(f):
            near[max(0, s - n_blend):e + n_blend] = True
        free = ~near & ~lowered
        leg = [foot.hip, foot.knee, foot.ankle]
        assert np.array_equal(out.rotations[free][:, leg], m.rotations[free][:, leg])
        checked += free.sum()
    # only the root's translation changes; vertically it only ever goes down; without the horizontal
    # follow step the root keeps its path horizontally
    moved = out.translations - m.translations
    assert np.abs(moved[:, 1:]).max() == 0.0 and (moved[:, 0, 1] <= 1e-12).all()
    fixed = lock_feet(m, con, follow=False).translations - m.translations
    assert np.abs(fixed[..., [0, 2]]).max() < 1e-12
    # the non-leg joints keep their local rotations everywhere
    legs = {j for f in con.feet for j in (f.hip, f.knee, f.ankle)}
    others = [j for j in range(m.n_joints) if j not in legs]
    assert np.allclose(out.rotations[:, others], m.rotations[:, others], atol=1e-12)


def test_the_cleaned_cycle_loops_and_its_held_feet_advance_by_the_travel():
    m = _planted_walk(n_frames=300, fps=60.0, noise_deg=0.3)[1]
    cycle = extract_cycle(m)
    cleaned, con = lock_cycle(cycle)
    N = cleaned.n_frames
    two = cleaned.repeat(2, root="motion")
    W = two.world_positions()
    # the seam: the step from frame N-1 to N is an ordinary step
    steps = np.linalg.norm(np.diff(W, axis=0), axis=-1).max(axis=1)
    assert steps[N - 1] < 1.5 * np.delete(steps, N - 1).max()
    # a held foot of cycle 2 is the same foot of cycle 1 moved by exactly the travel
    travel = cycle.drift[:3]
    for c, j in enumerate(con.joints):
        for s, e in ranges(con.mask[:, c]):
            if e <= N:
                # exact up to the fitted turn per cycle (a few hundredths of a degree here)
                assert np.allclose(W[s + N:e + N, j] - W[s:e, j], travel, atol=1e-3 * np.linalg.norm(travel))
                assert np.abs(W[s:e, j] - W[s, j]).max() < 1e-6
    # in place, a held foot slides back at exactly the treadmill speed
    inplace = cleaned.repeat(1, root="inplace").world_positions()
    for c, j in enumerate(con.joints):
        for s, e in ranges(con.mask[:, c]):
            if e - s >= 2:
                step = np.diff(inplace[s:e, j], axis=0)
                assert np.allclose(step, -travel / N, atol=1e-3 * np.linalg.norm(travel) / N)
    assert largest_leg_step(two) <= 1.5 * largest_leg_step(cycle.repeat(2, root="motion"))  # no knee pop


def test_skate_counts_feet_gliding_on_the_floor():
    still = synthetic_still(n_frames=30).motion
    assert skate(still) == pytest.approx(0.0, abs=1e-9)
    glide = still.translations.copy()
    glide[:, 0, 2] += np.arange(30) * 2.0        # 2 cm per frame at 60 fps, feet on the floor
    moving = Motion(still.skeleton, still.rotations, glide, still.frame_time)
    assert skate(moving) == pytest.approx(2.0 * 60.0, rel=1e-6)
    per = skate(moving, per_joint=True)
    assert set(per) == {"LeftFoot", "LeftToeBase", "RightFoot", "RightToeBase"}
    assert find_feet(still.skeleton)[0].side == "left"


def test_skate_on_a_leg_chain_needs_the_body_height():
    """A leg chain's positions (ChainArray) measure the same skate as the whole body's, given the body height;
    without it skate says so (body_height cannot read a chain)."""
    from mocycle.contacts import body_height
    from mocycle.contacts.legs import chain_joints, chain_positions, leg_joints

    walk = synthetic_walk(n_frames=120, fps=60, seed=5).motion
    feet = find_feet(walk.skeleton)
    W = chain_positions(walk, chain_joints(walk, leg_joints(feet)))
    body = body_height(walk)
    assert skate(walk, feet, positions=W, body=body) == pytest.approx(skate(walk, feet, body=body), rel=1e-9)
    with pytest.raises(TypeError, match="body"):
        skate(walk, feet, positions=W)


def test_far_from_its_holds_a_leg_is_unchanged():
    """With one contact per foot kept, the legs far from it (beyond the low frames, the blend and the
    swing bridge) keep their rotations exactly, and the held joints stand still to 1e-6."""
    from mocycle.contacts.detect import Contacts
    from mocycle.contacts.lock import BLEND_SECONDS, EXTEND_SECONDS

    m = _slid_walk()
    con = detect_contacts(m)
    mask = np.zeros_like(con.mask)
    for c in range(mask.shape[1]):
        rs = [r for r in con.joint_ranges(c) if r[0] > m.n_frames // 3]
        s, e = rs[0]
        mask[s:e, c] = True
    one = Contacts(con.feet, con.joints, con.foot_of, mask, con.up, con.body, con.frame_time)
    out = lock_feet(m, one, follow=False)
    W = out.world_positions()
    for c, j in enumerate(one.joints):
        for s, e in one.joint_ranges(c):
            assert np.abs(W[s:e, j] - W[s, j]).max() < 1e-6
    reach = int(round((EXTEND_SECONDS + BLEND_SECONDS) * m.fps)) + 1
    lowered = ~np.all(out.translations == m.translations, axis=(1, 2))
    checked = 0
    for f, foot in enumerate(one.feet):
        near = np.zeros(m.n_frames, bool)
        for s, e in one.foot_ranges(f):
            near[max(0, s - reach):e + reach] = True
        free = ~near & ~lowered
        leg = [foot.hip, foot.knee, foot.ankle]
        assert np.array_equal(out.rotations[free][:, leg], m.rotations[free][:, leg])
        checked += free.sum()
        assert not np.array_equal(out.rotations[near][:, leg], m.rotations[near][:, leg])
    assert checked > m.n_frames  # most frames of both legs are checked


def test_a_swinging_foot_clears_the_floor_and_a_held_or_unbounded_one_does_not():
    from mocycle.contacts.lock import HELD, LIFT_SECONDS, LOW, _lift

    T, dt, body = 60, 1 / 60, 170.0
    up = np.array([0.0, 1.0, 0.0])
    clear = 0.015 * body
    path = np.zeros((T, 3))
    path[:, 2] = np.arange(T) * 1.5 * body * dt      # 1.5 body heights/s along the floor: a swing, not a stance
    level = np.zeros(T, dtype=int)
    level[:10], level[50:] = HELD, LOW               # held before and after: frames 10-49 swing between holds
    lift = _lift(path, level, up, clear, body, dt)
    assert np.all(lift[level > 0] == 0)
    assert np.allclose(lift[20:40], clear)            # cleared fully away from the holds
    assert np.abs(np.diff(lift)).max() <= clear * dt / LIFT_SECONDS + 1e-12  # eased in and out, no drop
    slow = path.copy()
    slow[:, 2] = np.arange(T) * 0.1 * body * dt       # slower than a swing (maybe a missed stance): kept
    assert not _lift(slow, level, up, clear, body, dt).any()
    assert not _lift(path, np.zeros(T, dtype=int), up, clear, body, dt).any()  # no holds: nothing lifted


def test_soft_reach_eases_a_far_goal_in_and_leaves_near_ones():
    from mocycle.contacts.lock import _soft_reach

    hips = np.zeros((200, 3))
    base = np.tile([0.0, -80.0, 0.0], (200, 1))      # the captured ankle, 80 below the hip
    corr = np.zeros((200, 3))
    corr[:, 2] = np.linspace(0, 60, 200)               # a goal pulled farther and farther forward
    R, zone = np.full(200, 90.0), np.full(200, 3.0)
    out = _soft_reach(base, corr, hips, R, zone)
    d = np.linalg.norm(base + out - hips, axis=1)
    near = np.linalg.norm(base + corr - hips, axis=1) <= 87.0
    assert np.array_equal(out[near], corr[near])     # nearer than the zone: untouched
    assert d.max() < 90.0 and np.all(np.diff(d) > 0)  # never beyond the reach, still moving on
    assert np.abs(np.diff(d, 2)).max() < 0.05         # no corner where the clamp starts


def test_the_knee_turn_is_exact_about_an_axis_off_the_legs_plane():
    from scipy.spatial.transform import Rotation

    from mocycle.contacts.lock import _knee_turn

    rng = np.random.default_rng(3)
    u1 = rng.normal(size=(50, 3))
    u1 /= np.linalg.norm(u1, axis=1, keepdims=True)
    u2 = u1 + 0.6 * rng.normal(size=(50, 3))
    u2 /= np.linalg.norm(u2, axis=1, keepdims=True)
    plane = np.cross(u1, u2)
    n = plane / np.linalg.norm(plane, axis=1, keepdims=True) + 0.1 * rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    cos1 = np.sum(u1 * u2, axis=1) * 0.97 + 0.02      # near the current bend, reachable about n
    x = _knee_turn(u1, u2, n, cos1)
    turned = Rotation.from_rotvec(n * x[:, None]).apply(u2)
    assert np.allclose(np.sum(u1 * turned, axis=1), cos1, atol=1e-9)
    exact = plane / np.linalg.norm(plane, axis=1, keepdims=True)  # about the plane's normal: new minus old bend
    bend = np.arccos(np.sum(u1 * u2, axis=1))
    ok = bend < np.pi - 0.3
    assert ok.sum() > 40
    assert np.allclose(_knee_turn(u1, u2, exact, np.cos(bend + 0.2))[ok], 0.2)


def test_slow_is_measured_against_the_body_s_own_speed():
    still = synthetic_still(n_frames=60, fps=30).motion
    body = __import__("mocycle.contacts", fromlist=["body_height"]).body_height(still)
    moving = still.translations.copy()
    moving[:, 0, 2] += np.arange(60) * 0.25 * body / 30   # body and feet glide at 0.25 body heights/s
    glide = Motion(still.skeleton, still.rotations, moving, still.frame_time)
    assert not detect_contacts(glide).mask.any()                     # 0.25 is not slow in absolute terms
    assert not detect_contacts(glide, travel=0.2).mask.any()         # nor for a body this slow
    assert detect_contacts(glide, travel=1.2).mask.all(axis=0).all()  # slow for a body 1/1.2 times as fast


def _rocking_run(fps=60.0):
    """The synthetic run with its feet planted (:func:`plant_lowest_foot`) and its whole body rocking up
    and down by 1.2 % of its height three times a step: a stance that rocks vertically faster than the
    absolute ``CONTACT_RISE`` allows, as a fast run's fitted loop does (the jog 02_03 of the shared data)."""
    from mocycle.contacts import body_height, plant_lowest_foot
    from mocycle.datasets import synthetic_run

    take = synthetic_run(n_frames=int(6 * fps), fps=fps)
    m = plant_lowest_foot(take.motion)
    t = m.translations.copy()
    t[:, 0, 1] += 0.012 * body_height(m) * np.sin(2 * np.pi * 6 * take.unwrapped_phase)
    return Motion(m.skeleton, m.rotations, t, m.frame_time)


def test_a_run_whose_loop_loses_its_contacts_is_still_locked():
    cycle = extract_cycle(_rocking_run())
    ext = cycle.repeat(3, root="motion")
    assert not detect_contacts(ext, relax=False).mask.any()   # the usual rules find no stance at all
    con = detect_contacts(ext)
    N = cycle.n_frames
    for f in range(2):   # the rolling stance's rules: each foot planted in every cycle, for part of it
        share = con.foot_mask(f)[N:2 * N].mean()
        assert con.foot_ranges(f) and 0.05 < share < 0.6, share
    before = skate(cycle.repeat(2, root="motion"))
    kept, _ = lock_cycle(cycle, relax=False)
    locked, _ = lock_cycle(cycle)
    assert skate(kept.repeat(2, root="motion")) == pytest.approx(before)   # nothing held, nothing changed
    assert skate(locked.repeat(2, root="motion")) < 0.8 * before


def test_a_foot_held_up_is_not_planted_in_the_air(monkeypatch):
    """Standing on the right leg, the left lower leg swinging slowly back and forth well above the floor:
    the usual rules find no contact for it (it is slow only at the ends of its swing, high above its lowest
    level), and the rolling stance's rules, which take each joint's floor where it is slow, must not plant
    it there: its floor so found is far above the standing foot's."""
    from mocycle.contacts import detect
    from mocycle.rotations import axis_angle_quats

    still = synthetic_still(n_frames=90, fps=30).motion
    hip, knee = still.skeleton.index("LeftUpLeg"), still.skeleton.index("LeftLeg")
    q = still.rotations.copy()
    x = np.array([1.0, 0.0, 0.0])
    q[:, knee] = axis_angle_quats(x, np.full(90, 1.0))                # bent: hip to ankle 0.49 rad back
    q[:, hip] = axis_angle_quats(x, -0.49 - 0.5 * np.sin(2 * np.pi * np.arange(90) / 45))  # lowest mid-swing
    held_up = Motion(still.skeleton, q, still.translations, still.frame_time)
    up = np.array([0.0, 1.0, 0.0])
    W = held_up.world_positions()
    feet = find_feet(held_up.skeleton)
    assert W[:, feet[0].ankle, 1].min() > W[:, feet[1].ankle, 1].max() + 10   # the left foot is up
    con = detect_contacts(held_up, up=up)
    assert not detect_contacts(held_up, up=up, relax=False).foot_mask(0).any()
    assert not con.foot_mask(0).any()
    assert con.foot_mask(1).all()
    monkeypatch.setattr(detect, "RELAX_FLOOR", 1.0)   # without the floor check it would be planted in the air
    assert detect_contacts(held_up, up=up).foot_mask(0).any()


def test_a_low_frame_is_shifted_down_with_its_hold_only_near_the_contact():
    """A heel coming in above the height it is held at during its contact: the low frames before the contact
    keep its path horizontally held, and the downward shift eases out away from the contact (a heel coming in
    at speed is not pulled down to skim the floor); a shift up is kept whole."""
    from mocycle.contacts.lock import LOW, _own_holds

    T, up = 40, np.array([0.0, 1.0, 0.0])
    path = np.zeros((T, 3))
    path[:20, 1] = np.linspace(2.0, 1.0, 20)         # coming down
    path[20:30, 1] = np.linspace(1.0, 0.0, 10)       # the contact settles to 0: held at its lowest, 0
    mask = np.zeros(T, bool)
    mask[20:30] = True
    corr, level = _own_holds(path, mask, [np.zeros(3)], up, low=3.0, near=10.0, n_extend=12)
    assert np.all(level[8:20] == LOW) and np.all(level[:8] == 0)
    assert corr[19, 1] < -0.9 and abs(corr[8, 1]) < 0.1      # full shift beside the contact, none 12 frames off
    assert np.all(np.diff(corr[8:20, 1]) <= 1e-12)            # growing toward the contact
    assert np.allclose(corr[8:20, [0, 2]], 0.0)               # held horizontally
    corr, _ = _own_holds(path, mask, [np.array([0.0, 1.5, 0.0])], up, low=3.0, near=10.0, n_extend=12)
    assert np.allclose(corr[8:20, 1], 0.5)                    # held higher than it came in: shifted up whole


def _bent(motion, deg_per_unit):
    """``motion`` with its root's path bent onto a circle (``deg_per_unit`` degrees of turn per unit of
    travel) and the body turned with it: a turning walk whose planted feet stay nearly planted."""
    from scipy.spatial.transform import Rotation

    root = motion.translations[:, 0]
    d = root[-1] - root[0]
    f = np.array([d[0], 0.0, d[2]]) / np.hypot(d[0], d[2])
    side = np.cross([0.0, 1.0, 0.0], f)
    rel = root - root[0]
    s, lat = rel @ f, rel @ side
    k = np.radians(deg_per_unit)
    phi = k * s
    t = motion.translations.copy()
    t[:, 0] = (root[0] + np.outer(np.sin(phi) / k - lat * np.sin(phi), f)
               + np.outer((1 - np.cos(phi)) / k + lat * np.cos(phi), side) + np.outer(rel[:, 1], [0.0, 1.0, 0.0]))
    q = motion.rotations.copy()
    q[:, 0] = (Rotation.from_rotvec(np.outer(phi, [0.0, 1.0, 0.0])) * Rotation.from_quat(q[:, 0])).as_quat()
    return Motion(motion.skeleton, q, t, motion.frame_time)


@pytest.mark.parametrize("deg_per_unit", [0.0, 0.2])   # straight, and about 25 degrees per cycle
def test_a_turning_loop_holds_each_foot_across_its_seam(deg_per_unit):
    """Each repeat of a turning loop is the one before turned about its first frame: a contact across the
    seam is held at one place seen from either side (the hips' follow shift turns with the loop and is 0 at
    the first frame, so the repeats meet)."""
    m = _planted_walk(n_frames=360, fps=60.0, noise_deg=0.3)[1]
    if deg_per_unit:
        m = _bent(m, deg_per_unit)
    cycle = extract_cycle(m)
    assert abs(np.degrees(cycle.drift[3]) - deg_per_unit * np.linalg.norm(cycle.drift[:3])) < 3.0
    cleaned, con = lock_cycle(cycle)
    W = cleaned.repeat(3, root="motion").world_positions()
    crossing = 0
    for c, j in enumerate(con.joints):
        crossing += bool(con.mask[0, c] and con.mask[-1, c])
        for s, e in ranges(np.tile(con.mask[:, c], 3)):
            assert np.abs(W[s:e, j] - W[s, j]).max() < 1e-6 * np.linalg.norm(cycle.drift[:3])
    assert crossing   # the test is about a contact over the seam
