"""Foot locking (Kovar, Schreiner and Gleicher 2002, "Footskate cleanup for motion capture editing").

1. **Hips follow the planted feet.** The root is first moved horizontally by
   the opposite of the hold-weighted mean horizontal velocity of the planted
   contact joints (less its mean over the take, or over one period of a
   repeated loop, so the travel is kept): in single support the stance foot
   then stands still with no change to the legs at all.
2. **Holds.** Each contact of a contact joint is held at one point in world
   space: at the joint's lowest height during the contact and horizontally at
   its mean position, or at one of its positions during the contact when that
   needs less lowering of the root.  The toe of a foot whose ankle and toe are
   both held is held at the ankle's point plus the foot vector in the middle
   of their overlap, so a rigid foot meets both holds exactly; a heel that comes
   down again within the same toe contact is held where the rigid foot puts it
   about the toe's hold (held at its own place it would pull the held toe away).
   While only one of the foot's joints is held, the other is carried with it
   rigidly (the foot keeps its own roll), and where a held (or low) toe leaves
   the ankle beyond the leg's reach the heel lifts (the foot turns about the
   toe).
3. **Low frames around a contact.** Before and after each contact, while the
   joint is still within ``EXTEND_HEIGHT`` of the held height and within
   ``EXTEND_DISTANCE`` of the held point (at most ``EXTEND_SECONDS``), it is
   held horizontally and keeps its own vertical path: a heel coming down or a
   toe lifting away moves straight down or up instead of gliding on the floor.
   Its path is shifted vertically as at the contact's edge; a downward shift
   (a contact held lower than the joint came in) eases out away from the
   contact, so a heel coming in at speed is not pulled down to skim the floor.
   Where both joints of a foot are low, the one nearer its own contact leads
   and the other is carried with it; a joint handed over between its own hold
   and being carried is eased over ``blend`` seconds.
4. **Swings.** Between two holds of a joint (a gap of at most
   ``BRIDGE_SECONDS``) the correction goes from the one hold's to the next's
   by a smoothstep, so a swing foot keeps the shape of its world path, only
   shifted; longer gaps and the ends of a take fade the correction out over
   ``blend`` seconds.  A joint between two holds that moves faster than
   ``SWING_SPEED`` clears its *swing clearance* above its lowest level (a
   swinging foot does not skim the floor; the lift is rate-limited): by
   default the capture's own (:mod:`~mocycle.contacts.clearance`).
5. **Root lowering.** Where a held ankle goal is still farther from its hip
   than ``reach`` of the leg's length, the root goes down along the vertical
   (smoothed over the blend window so it never jumps and is never less than
   needed); every foot keeps its goal in the world, so a swing foot does not
   dip with the root.  Goals not held are then brought within reach softly
   (soft IK: raised, or pulled toward the hip, with an exponential ease); next
   to a held frame they are brought within the reach as the held ones are and
   eased to the soft reach over the blend, so a leg leaving a hold nearly
   straight (a toe-off) is not bent by the soft zone in one frame.
6. **Two-bone IK.** The knee bends about the normal of the hip-knee-ankle
   plane until the hip-ankle distance is right, then the thigh swings by the
   smallest rotation that puts the ankle on its goal (the knee stays in the
   leg's plane, only turned with it; a nearly straight knee bends about the
   leg's usual axis); the foot keeps its world orientation,
   turned by the smallest rotation that points it at the toe goal.

Only local rotations of hips, knees and ankles change, and the travel
joint's translation, so every bone keeps its length exactly.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..motion import Motion
from ..rotations import axis_rotations
from .clearance import SWING_SPEED, swing_clearance
from .detect import Contacts, ranges
from .legs import ChainArray, along, chain_joints, chain_positions, chain_rotation_blocks, leg_joints
from .smooth import maximum, uniform

BLEND_SECONDS = 0.1  # cross-fade in and out of each contact
REACH = 0.995        # of hip-knee plus knee-ankle: farther goals lower the root
DISTANCE_WEIGHT = 1.0  # a hold this much farther from the mean weighs like the same lowering of the root
EXTEND_SECONDS = 0.2   # a hold reaches at most this far beyond its contact while the joint stays low
EXTEND_HEIGHT = 0.025  # of the body height above the held height: "low" (the contact detector's height)
EXTEND_DISTANCE = 0.03  # of the body height: "near" the held point horizontally (farther: no early plant)
STRAIGHT_KNEE = 0.1   # sine of the knee angle below which the bend axis eases to the leg's usual one
SOFT_ZONE = 0.03      # of the leg's length: a free goal this close to the reach eases in (soft IK)
SLOW_SPEED = 0.25      # body heights/s: a free foot this slow is not lifted (it may be a stance the detector missed)
LIFT_SECONDS = 0.1     # the lift changes by at most the clearance in this time
BRIDGE_SECONDS = 0.6   # a gap between holds this short (a swing) is bridged; longer ones fade over the blend
#: how firmly a contact joint is held on a frame: its own contact, its foot's other joint's contact (carried
#: rigidly), its own low frames around a contact (held horizontally), the other joint's low frames
HELD, FOLLOW, LOW, FOLLOW_LOW = 4, 3, 2, 1


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _windows(first: np.ndarray, count: np.ndarray, step: int) -> tuple[np.ndarray, np.ndarray]:
    """The frames ``(M,)`` of windows that start at ``first`` ``(k,)`` and run ``count`` ``(k,)`` frames on in the
    direction ``step`` (+1 or -1), window after window, and the window ``(M,)`` each belongs to."""
    count = np.maximum(count, 0)
    owner = np.repeat(np.arange(first.size), count)
    pos = np.arange(owner.size) - np.repeat(np.cumsum(count) - count, count)
    return first[owner] + step * pos, owner


def _contact_ends(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and stops ``(k,)`` (exclusive) of the contacts of one joint."""
    rs = np.array(ranges(mask), dtype=int).reshape(-1, 2)
    return rs[:, 0], rs[:, 1]


def _hold_weights(mask: np.ndarray, n_blend: int) -> np.ndarray:
    """Weights ``(T,)`` of one contact joint: 1 inside each contact, smoothstep ramps of ``n_blend`` frames
    (at most half the gap to the neighbour contact) outside."""
    T = mask.shape[0]
    w = mask.astype(np.float64)
    a, b = _contact_ends(mask)
    if a.size == 0:
        return w
    r_in = np.minimum(n_blend, (a - np.concatenate([[-2 * n_blend], b[:-1]])) // 2)
    r_out = np.minimum(n_blend, (np.concatenate([a[1:], [T + 2 * n_blend]]) - b) // 2)
    t, k = _windows(a - 1, np.minimum(r_in, a), -1)
    w[t] = _smoothstep((t - (a[k] - r_in[k] - 1)) / (r_in[k] + 1))
    t, k = _windows(b, np.minimum(r_out, T - b), 1)
    w[t] = _smoothstep((b[k] + r_out[k] - t) / (r_out[k] + 1))
    return w


def _normalize(v: np.ndarray) -> np.ndarray:
    n = _norms(v)[..., None]
    return v / np.maximum(n, 1e-300)


def _squares(v: np.ndarray) -> np.ndarray:
    """``np.sum(v * v, axis=-1)`` of 3-vectors ``(..., 3)``, bit for bit (summed in its order), without numpy's
    reduction over a short last axis."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return x * x + y * y + z * z


def _norms(v: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(v, axis=-1)`` of 3-vectors ``(..., 3)``, bit for bit (as
    :func:`~mocycle.rotations.vector_norms`, with fewer numpy calls: these arrays are short)."""
    return np.sqrt(_squares(v))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of ``(T, 3)`` arrays (``np.cross`` without its axis handling: it is called
    on short arrays many times)."""
    out = np.empty(a.shape)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _swing(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotations ``(T, 3, 3)`` turning the directions of ``a`` into those of ``b`` ``(T, 3)``."""
    a, b = _normalize(a), _normalize(b)
    axis = _cross(a, b)
    s = _norms(axis)
    angle = np.arctan2(s, np.sum(a * b, axis=-1))
    rotvec = _normalize(axis) * angle[:, None]
    return Rotation.from_rotvec(rotvec).as_matrix()


def _leg_length(W: ChainArray, foot) -> np.ndarray:
    """Hip-knee plus knee-ankle ``(T,)``."""
    H, K, A = W[:, foot.hip], W[:, foot.knee], W[:, foot.ankle]
    return _norms(K - H) + _norms(A - K)


def _reach(W: ChainArray, foot, reach: float) -> np.ndarray:
    """How far ``(T,)`` a held ankle may be from its hip: ``reach`` of the leg's length (a held knee never
    goes fully straight, where a millimetre of length takes a large knee angle)."""
    return np.maximum(reach * _leg_length(W, foot), _norms(W[:, foot.ankle] - W[:, foot.hip]))


def _need(goals: np.ndarray, hips: np.ndarray, R: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Smallest lowering ``delta >= 0`` of the hips along ``-up`` putting each goal within ``R`` of its hip
    (as close as it gets when the goal is too far sideways); broadcasts over leading axes."""
    d = goals - hips
    du = along(d, up)
    disc = du * du - _squares(d) + R * R
    return np.maximum(np.where(disc >= 0, -du - np.sqrt(np.maximum(disc, 0.0)), -du), 0.0)


def _best_hold(path: np.ndarray, offsets: np.ndarray, hips: np.ndarray, R: np.ndarray, up: np.ndarray,
               body: float) -> np.ndarray:
    """Where to hold a contact: at the joint's lowest height during the contact, and horizontally at one of
    its positions during the contact or their mean: the one whose
    ankle goals (hold + ``offsets``, ``(m, 3)``) need the least lowering of the root, then the one nearest
    the mean (``DISTANCE_WEIGHT`` × the distance to the mean weighs like the same lowering)."""
    floor = (path @ up).min()
    mean = path.mean(axis=0)
    cands = np.concatenate([mean[None], path])                        # (n, 3)
    cands = cands + (floor - cands @ up)[:, None] * up                # planted at the contact's lowest point
    mean = cands[0]
    need = _need(cands[:, None, :] + offsets[None], hips[None], R[None], up).max(axis=1)
    cost = need + DISTANCE_WEIGHT * _norms(cands - mean)
    k = int(np.argmin(cost))
    return cands[0] if need[0] <= need[k] + 1e-6 * body else cands[k]


def _own_holds(path: np.ndarray, mask: np.ndarray, targets: list[np.ndarray], up: np.ndarray, low: float,
               near: float, n_extend: int) -> tuple[np.ndarray, np.ndarray]:
    """Corrections ``(T, 3)`` (NaN where not held) and levels ``(T,)`` of one contact joint's own holds.

    In each contact the correction takes the joint to its target (level ``HELD``).  Around it, while the
    joint stays within ``low`` of the target's height and within ``near`` of it horizontally (at most
    ``n_extend`` frames and a third of the gap to the neighbour contact), it is held horizontally and
    keeps its own vertical path, shifted as at the contact's edge (level ``LOW``); a downward shift eases
    out over ``n_extend`` frames away from the contact.
    """
    T = path.shape[0]
    corr = np.full((T, 3), np.nan)
    level = np.zeros(T, dtype=int)
    a, b = _contact_ends(mask)
    if a.size == 0:
        return corr, level
    goal = np.asarray(targets, dtype=np.float64).reshape(-1, 3)
    held = np.flatnonzero(mask)
    corr[held] = goal[np.repeat(np.arange(a.size), b - a)] - path[held]
    level[held] = HELD
    height = path @ up
    third = (a[1:] - b[:-1]) // 3
    n_before = np.minimum(np.minimum(n_extend, np.concatenate([[n_extend], third])), a)
    n_after = np.minimum(np.minimum(n_extend, np.concatenate([third, [n_extend]])), T - b)
    for first, count, edge, step in ((a - 1, n_before, a, -1), (b, n_after, b - 1, 1)):
        f, k = _windows(first, count, step)
        if f.size == 0:
            continue
        c = goal[k] - path[f]
        cu = c @ up
        ok = (height[f] < goal[k] @ up + low) & (_norms(c - cu[:, None] * up) <= near)
        misses = np.cumsum(~ok)                                     # up to the first miss of each window
        keep = misses == np.concatenate([[0], misses])[np.cumsum(count) - count][k]
        f, k, c, cu = f[keep], k[keep], c[keep], cu[keep]
        edge_u = (goal[k] - path[edge[k]]) @ up
        # a joint held lower than it came in (or left) moves down with the hold only near the contact: the
        # shift eases out over the low frames, so a heel coming in at speed is not pulled down to skim
        # the floor from far away
        ease = 1.0 - _smoothstep((np.abs(f - first[k]) + 1) / (n_extend + 1))
        edge_u = np.where(edge_u < 0, edge_u * ease, edge_u)
        corr[f] = c + (edge_u - cu)[:, None] * up
        level[f] = LOW
    return corr, level


def _frames_from(mask: np.ndarray) -> np.ndarray:
    """``(T,)`` frames from each frame to the nearest True of ``mask`` (``inf`` without any)."""
    T = mask.shape[0]
    hits = np.flatnonzero(mask)
    if hits.size == 0:
        return np.full(T, np.inf)
    k = np.clip(np.searchsorted(hits, np.arange(T)), 1, hits.size) - 1
    nxt = hits[np.minimum(k + 1, hits.size - 1)]
    return np.minimum(np.abs(np.arange(T) - hits[k]), np.abs(nxt - np.arange(T))).astype(float)


def _follow(corr: np.ndarray, level: np.ndarray, other: np.ndarray, other_level: np.ndarray) -> None:
    """Where the other contact joint of the same foot holds and this one does not (as strongly), this one
    moves with it: the foot is carried rigidly (in place, levels ``FOLLOW`` and ``FOLLOW_LOW``)."""
    for own, theirs in ((FOLLOW, HELD), (FOLLOW_LOW, LOW)):
        m = (other_level == theirs) & (level < own)
        corr[m] = other[m]
        level[m] = own


def _bridge(corr: np.ndarray, n_bridge: int, n_fade: int) -> np.ndarray:
    """Fill the NaN frames of ``corr`` ``(T, 3)``: a gap of at most ``n_bridge`` frames between two held
    frames goes from one correction to the other by a smoothstep; a longer gap, or one at an end of the
    take, fades each side's correction to zero over ``n_fade`` frames."""
    out = corr.copy()
    T = corr.shape[0]
    p, q = _contact_ends(np.isnan(corr[:, 0]))      # the gaps [p, q)
    if p.size == 0:
        return out
    t, k = _windows(p, q - p, 1)
    p, q = p[k], q[k]
    before, after = p > 0, q < T
    c0 = np.where(before[:, None], corr[np.maximum(p - 1, 0)], 0.0)
    c1 = np.where(after[:, None], corr[np.minimum(q, T - 1)], 0.0)
    bridged = before & after & (q - p <= n_bridge)
    fade0 = np.where(before, _smoothstep((p + n_fade - t) / (n_fade + 1)), 0.0)
    fade1 = np.where(after, _smoothstep((t - (q - 1 - n_fade)) / (n_fade + 1)), 0.0)
    faded = fade0[:, None] * c0 + fade1[:, None] * c1
    out[t] = np.where(bridged[:, None], c0 + _smoothstep((t - p + 1) / (q - p + 1))[:, None] * (c1 - c0), faded)
    return out


def _soft_reach(base: np.ndarray, corr: np.ndarray, hips: np.ndarray, R: np.ndarray,
                zone: np.ndarray, up: np.ndarray | None = None) -> np.ndarray:
    """``corr`` ``(T, 3)`` changed so that ``base + corr`` stays within ``R`` ``(T,)`` of ``hips``, softly
    (soft IK): a goal within ``zone`` ``(T,)`` of ``R`` (or beyond ``base``'s own distance, if that is
    farther in) is pulled toward the hip by an exponential ease, so a leg straightens gradually as its goal
    runs away and never snaps straight.  With ``up`` the goal is raised along it (its horizontal place
    kept) where that is enough, else pulled toward the hip.  ``corr`` is unchanged where the goal is nearer
    than that."""
    v = base + corr - hips
    d = _norms(v)
    raw = _norms(base - hips)
    start = np.minimum(np.maximum(R - zone, raw), R)
    room = R - start
    out = corr.copy()
    far = d > start
    x = (d[far] - start[far]) / np.maximum(room[far], 1e-12 * d[far])
    D = start[far] + room[far] * -np.expm1(-x)
    vf = v[far]
    radial = vf * (D / d[far])[:, None]
    if up is not None:  # raised straight up where that reaches: a foot held horizontally keeps its place
        vu = vf @ up
        disc = vu ** 2 - d[far] ** 2 + D ** 2
        s = -vu - np.sqrt(np.maximum(disc, 0.0))
        radial = np.where((disc >= 0)[:, None], vf + np.outer(s, up), radial)
    out[far] = hips[far] + radial - base[far]
    return out


def _foot_goals(W: ChainArray, contacts: Contacts, f: int, n_extend: int, n_bridge: int, n_fade: int,
                R: np.ndarray, clearance: np.ndarray):
    """Ankle goal ``(T, 3)``, toe goal ``(T, 3)`` or None, ``(T,)`` True where the foot is held (the ankle
    holds or follows its hold) and ``(T,)`` True where either goal differs from the capture.  ``R``: the
    leg's :func:`_reach` ``(T,)``."""
    foot = contacts.feet[f]
    up, body = contacts.up, contacts.body
    low, near = EXTEND_HEIGHT * body, EXTEND_DISTANCE * body
    cols = {contacts.joints[c]: c for c, g in enumerate(contacts.foot_of) if g == f}
    a, hips = W[:, foot.ankle], W[:, foot.hip]
    ma = contacts.mask[:, cols[foot.ankle]]
    ra = ranges(ma)
    mt = contacts.mask[:, cols[foot.toe]] if foot.toe is not None else np.zeros_like(ma)
    rt = ranges(mt)
    t = W[:, foot.toe] if foot.toe is not None else a
    # each toe contact with the ankle contact it overlaps most: one rigid-foot hold
    partner = {}
    stops_a = [y for _, y in ra]
    for i, (s, e) in enumerate(rt):
        k, overlap = _most_overlap(ra, stops_a, s, e)
        if overlap >= 0:  # overlapping or back to back: one rigid-foot hold
            partner[i] = (k, _middle((s, e), ra[k]))
    toes_of: dict[int, list[tuple[int, int]]] = {}  # ankle contact -> its partner toe contacts and their middles
    for i, (k, mid) in partner.items():
        toes_of.setdefault(k, []).append((i, mid))
    held_a = []
    for k, (s, e) in enumerate(ra):
        frames = [np.arange(s, e)]
        offsets = [np.zeros((e - s, 3))]
        for i, mid in toes_of.get(k, ()):  # toe-only frames of the partner contact: the ankle follows the held toe
            only = np.arange(*rt[i])
            only = only[~ma[only]]
            frames.append(only)
            offsets.append((t[mid] - a[mid]) - (t[only] - a[only]))
        fr, off = np.concatenate(frames), np.concatenate(offsets)
        held_a.append(_best_hold(a[s:e], off, hips[fr], R[fr], up, body))
    _heels_about_toes(held_a, ra, rt, partner, a, t)
    corr_a, level_a = _own_holds(a, ma, held_a, up, low, near, n_extend)
    corr_t = None
    if foot.toe is not None:
        ankle = _Contact(path=a, mask=ma, runs=ra, held=held_a, corr=corr_a, level=level_a)
        toe = _Contact(path=t, mask=mt, runs=rt)
        _toe_holds(ankle, toe, partner, _Holding(hips=hips, reach=R, up=up, body=body, low=low, near=near,
                                                 n_extend=n_extend, n_ease=n_fade))
        corr_t, level_t = toe.corr, toe.level
    corr_a = _bridge(corr_a, n_bridge, n_fade)
    clear = clearance * body
    clear_a, clear_t = clear[cols[foot.ankle]], clear[cols[foot.toe]] if foot.toe is not None else 0.0
    corr_a += np.outer(_lift(a + corr_a, level_a, up, clear_a, body, contacts.frame_time), up)
    changed = np.any(corr_a != 0, axis=1)
    if corr_t is None:
        return a + corr_a, None, level_a >= FOLLOW, changed
    corr_t = _bridge(corr_t, n_bridge, n_fade)
    corr_t += np.outer(_lift(t + corr_t, level_t, up, clear_t, body, contacts.frame_time), up)
    return a + corr_a, t + corr_t, level_a >= FOLLOW, changed | np.any(corr_t != 0, axis=1)


def _most_overlap(runs: list, stops: list, s: int, e: int) -> tuple[int, int]:
    """Of ``runs`` (disjoint ``(start, stop)`` in order; ``stops`` their stops), the first that overlaps ``[s, e)``
    most and by how many frames (0 back to back; ``(-1, -1)`` when none overlaps or touches): found by bisection,
    so that the contacts of a long take are paired in ``O(n log n)``."""
    lo = bisect.bisect_left(stops, s)   # the first run that ends at s or later
    best, most = -1, -1
    for k in range(lo, len(runs)):
        x, y = runs[k]
        if x > e:
            break
        overlap = min(e, y) - max(s, x)
        if overlap > most:
            best, most = k, overlap
    return best, most


def _middle(r: tuple[int, int], q: tuple[int, int]) -> int:
    """The middle frame of the overlap of runs ``r`` and ``q`` (``(start, stop)``; back to back: the last of the
    first)."""
    return (max(r[0], q[0]) + min(r[1], q[1]) - 1) // 2


def _heels_about_toes(held_a: list, ra: list, rt: list, partner: dict, a: np.ndarray, t: np.ndarray) -> None:
    """Re-hold (in ``held_a``, in place) each ankle contact that lies within a toe contact whose rigid-foot hold
    is made with another ankle contact (``partner``, :func:`_foot_goals`): a heel that lifts and comes down
    again while the toe stays, or, in a loop's repeats, one long toe contact beside each repeat's heel
    contact.  Held at its own place the heel would pull the held toe to where the foot puts it (a jump of
    the toe as that heel contact starts, and back as it ends); it is held instead where the rigid foot puts
    it about the toe's hold, in the middle of their overlap.  ``ra``, ``rt``: the ankle's and the toe's
    contacts; ``a``, ``t``: their paths ``(T, 3)``."""
    partners = {k for k, _ in partner.values()}
    stops_t = [e for _, e in rt]
    for k, (x, y) in enumerate(ra):
        i, overlap = _most_overlap(rt, stops_t, x, y)  # the toe contact this ankle contact overlaps most
        if overlap <= 0 or k in partners or i not in partner:
            continue
        k0, mid0 = partner[i]
        mid = _middle(rt[i], ra[k])
        held_a[k] = held_a[k0] + (t[mid0] - a[mid0]) + (a[mid] - t[mid])


def _lift(path: np.ndarray, level: np.ndarray, up: np.ndarray, clear: float, body: float,
          frame_time: float) -> np.ndarray:
    """How far ``(T,)`` to raise a contact joint's goal ``path`` ``(T, 3)`` where it swings (``level`` 0
    between two of its holds) and moves on: a foot moving faster than ``SWING_SPEED`` body heights per
    second is swinging, and a swinging foot clears ``clear`` above its lowest level (it does not glide
    along the floor, as a heel coming in at full speed or a toe dragged forward does).  The lift fades in
    from ``SLOW_SPEED``; it changes by at most ``clear`` per ``LIFT_SECONDS`` (a heel lands, it does not
    drop)."""
    T = path.shape[0]
    if T < 2:
        return np.zeros(T)
    h = path @ up
    h = h - h.min()
    v = np.gradient(path, frame_time, axis=0)
    v = _norms(v - np.outer(v @ up, up)) / body
    ramp = np.clip((v - SLOW_SPEED) / (SWING_SPEED - SLOW_SPEED), 0.0, 1.0)
    holds = np.flatnonzero(level)
    if holds.size == 0:   # a foot without contacts (or a missed stance) stays
        return np.zeros(T)
    frames = np.arange(T)
    swing = (level == 0) & (frames > holds[0]) & (frames < holds[-1])   # between two holds
    lift = np.where(swing, np.maximum(clear - h, 0.0) * ramp, 0.0)
    rate = clear * frame_time / LIFT_SECONDS
    # rate-limited: lift[t] = min over s of lift[s] + rate |t - s| (a running minimum each way)
    lift = np.minimum(lift, rate * frames + np.minimum.accumulate(lift - rate * frames))
    return np.minimum(lift, np.minimum.accumulate((lift + rate * frames)[::-1])[::-1] - rate * frames)


@dataclass
class _Contact:
    """One contact joint of a foot (ankle or toe) while its holds are made: ``path`` ``(T, 3)`` (world),
    ``mask`` ``(T,)`` True in contact, ``runs`` its contacts (``[start, end)``); then ``held`` (the place each
    contact is held at), ``corr`` ``(T, 3)`` (the correction of ``path``) and ``level`` ``(T,)`` (how it is
    held: :func:`_own_holds`)."""

    path: np.ndarray
    mask: np.ndarray
    runs: list
    held: list = field(default_factory=list)
    corr: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    level: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


@dataclass(frozen=True)
class _Holding:
    """What the holds of one foot are made with: the hip's path ``hips`` ``(T, 3)`` and the leg's ``reach``
    ``(T,)``; the take's ``up`` and ``body`` height; ``low``, ``near`` and ``n_extend``, how far around a
    contact a joint stays held (:func:`_own_holds`); ``n_ease`` frames to ease a carried joint."""

    hips: np.ndarray
    reach: np.ndarray
    up: np.ndarray
    body: float
    low: float
    near: float
    n_extend: int
    n_ease: int


def _toe_holds(ankle: _Contact, toe: _Contact, partner: dict, h: _Holding) -> None:
    """The toe's holds, corrections (NaN where not held) and levels, set on ``toe``; the ankle's ``corr``
    and ``level`` changed in place where it follows the held toe (heel lifted where the leg cannot reach).
    ``partner`` maps a toe contact to the ankle contact it overlaps most and the middle frame of the two
    (one rigid-foot hold)."""
    a, t, held_a, corr_a, level_a = ankle.path, toe.path, ankle.held, ankle.corr, ankle.level
    hips, R, up, body = h.hips, h.reach, h.up, h.body
    held_t = []
    for i, (s, e) in enumerate(toe.runs):
        if i in partner:  # a rigid foot can meet both holds: toe = held ankle + foot vector
            k, mid = partner[i]
            held_t.append(held_a[k] + (t[mid] - a[mid]))
        else:
            fr = np.arange(s, e)
            held_t.append(_best_hold(t[s:e], a[fr] - t[fr], hips[fr], R[fr], up, body))
    corr_t, level_t = _own_holds(t, toe.mask, held_t, up, h.low, h.near, h.n_extend)
    toe.held, toe.corr, toe.level = held_t, corr_t, level_t
    # both low around a contact: the joint nearer its own contact leads and the other is carried with it
    # (the heel leads a landing, the toe a push-off), so the foot keeps its own roll and is not stretched
    # between two holds and then let go
    both = (level_a == LOW) & (level_t == LOW)
    if both.any():
        da, dt = _frames_from(level_a == HELD), _frames_from(level_t == HELD)
        for lead, (c_own, l_own, c_other) in (((dt < da), (corr_a, level_a, corr_t)),
                                                ((da <= dt), (corr_t, level_t, corr_a))):
            m = both & lead
            c_own[m] = c_other[m]
            l_own[m] = FOLLOW_LOW
    _follow(corr_a, level_a, corr_t, level_t)
    _follow(corr_t, level_t, corr_a, level_a)
    # a held toe with the ankle out of the leg's reach: the heel lifts (the foot turns about the toe) until
    # the ankle is back within reach, rather than the root going down
    on_toe = (level_a == FOLLOW) | (level_a == FOLLOW_LOW)
    if on_toe.any():
        length = _norms(t[on_toe] - a[on_toe])
        goal_t = t[on_toe] + corr_t[on_toe]
        lifted = _within_reach(a[on_toe] + corr_a[on_toe], goal_t, length, hips[on_toe], R[on_toe])
        corr_a[on_toe] = lifted - a[on_toe]
    _ease_carried(corr_a, level_a, h.n_ease)
    _ease_carried(corr_t, level_t, h.n_ease)
    if on_toe.any():  # still one foot length from the held toe (the toe is aimed at, so it stays put)
        goal_t = t[on_toe] + corr_t[on_toe]
        length = _norms(t[on_toe] - a[on_toe])
        corr_a[on_toe] = goal_t + length[:, None] * _normalize(a[on_toe] + corr_a[on_toe] - goal_t) - a[on_toe]


def _ease_carried(corr: np.ndarray, level: np.ndarray, n: int) -> None:
    """Where a contact joint goes from its own hold to being carried with the other joint of its foot (or
    back), the jump between the two corrections is eased out over ``n`` frames of the carried run, so a
    heel let go while the toe still holds rises over a few frames instead of popping up, and a toe coming
    down about a held heel lands on its hold without a snap (in place)."""
    T = corr.shape[0]
    for p, q in ranges((level == FOLLOW) | (level == FOLLOW_LOW)):
        t = np.arange(p, min(q, p + n))
        if p > 0 and level[p - 1] == HELD:
            corr[t] += np.outer(1.0 - _smoothstep((t - p + 1) / (n + 1)), corr[p - 1] - corr[p])
        t = np.arange(max(p, q - n), q)
        if q < T and level[q] == HELD:
            corr[t] += np.outer(_smoothstep((t - (q - n - 1)) / (n + 1)), corr[q] - corr[q - 1])


def _within_reach(p: np.ndarray, c1: np.ndarray, r1: np.ndarray, c2: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """``p`` on the sphere ``(c1, r1)`` moved along it to the nearest point within ``r2`` of ``c2`` (where
    it is out of reach and the spheres meet; unchanged elsewhere).  All ``(T, 3)`` / ``(T,)``."""
    out = p.copy()
    far = _norms(p - c2) > r2
    axis = c2 - c1
    d = _norms(axis)
    a = (d ** 2 + r1 ** 2 - r2 ** 2) / (2 * np.maximum(d, 1e-300))
    meet = far & (d > 1e-12) & (np.abs(a) <= r1)
    if meet.any():
        n = axis[meet] / d[meet, None]
        centre = c1[meet] + a[meet, None] * n
        radius = np.sqrt(np.maximum(r1[meet] ** 2 - a[meet] ** 2, 0.0))
        q = p[meet] - centre
        q = q - np.sum(q * n, axis=1, keepdims=True) * n
        out[meet] = centre + radius[:, None] * _normalize(q)
    return out


def _lowering(W: ChainArray, contacts: Contacts, goals: list[np.ndarray], weights: list[np.ndarray],
              reaches: list[np.ndarray], n_blend: int) -> np.ndarray:
    """How far ``(T,)`` the root must go down so every held ankle goal (weight > 0) is within reach (``reaches``:
    each leg's :func:`_reach` ``(T,)``), smoothed so it is never less."""
    need = np.zeros(W.shape[0])
    for foot, g, w, R in zip(contacts.feet, goals, weights, reaches, strict=True):
        need = np.maximum(need, np.where(w > 0, _need(g, W[:, foot.hip], R, contacts.up), 0.0))
    if not need.any():
        return need
    width = 2 * max(1, n_blend) + 1
    delta = uniform(maximum(need, width), width)
    return np.where(delta > 1e-9 * contacts.body, delta, 0.0)  # no round-off tails: untouched frames stay exact


def _bend_axis(hip_bends: np.ndarray, hip_thighs: np.ndarray) -> np.ndarray:
    """The leg's usual bend axis ``(3,)`` in the thigh's frame: the mean of ``thigh x shin`` weighted by the bend,
    from ``hip_bends`` ``(T, 3)``, each frame's ``thigh x shin`` in the hip's frame (``Rw_hipᵀ (u1 x u2)``),
    and ``hip_thighs`` ``(T, 3)``, the thigh in the hip's frame (``Rw_hipᵀ u1``: a never-bent leg's axis is
    across it)."""
    local = hip_bends.sum(axis=0)
    if np.linalg.norm(local) < 1e-9:  # never bent: any axis across the leg
        local = np.cross(hip_thighs.mean(axis=0), [0.0, 0.0, 1.0])
        if np.linalg.norm(local) < 1e-9:
            local = np.array([1.0, 0.0, 0.0])
    return local / np.linalg.norm(local)


def _bend_normals(Rw_hip: np.ndarray, u1: np.ndarray, u2: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Unit normals ``(T, 3)`` of the hip-knee-ankle plane, eased toward the leg's usual bend ``axis``
    (:func:`_bend_axis`) as the knee straightens: ``thigh x shin`` (its length is the sine of the knee angle)
    plus ``STRAIGHT_KNEE`` times the axis turned with the thigh.  A nearly straight knee, whose own plane is
    undefined or turns fast, so bends about its usual axis, and the normal never jumps."""
    return _normalize(_cross(u1, u2) + STRAIGHT_KNEE * np.einsum("tij,j->ti", Rw_hip, axis))


def _thigh_shin(W, foot, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Hip, knee and ankle positions ``(n, 3)`` at the frames ``t``, the thigh and shin lengths ``(n,)`` and
    unit directions ``(n, 3)``: ``H, K, A, l1, l2, u1, u2``."""
    H, K, A = W[t, foot.hip], W[t, foot.knee], W[t, foot.ankle]
    l1 = _norms(K - H)
    l2 = _norms(A - K)
    return H, K, A, l1, l2, (K - H) / l1[:, None], (A - K) / l2[:, None]


def _knee_turn(u1: np.ndarray, u2: np.ndarray, n: np.ndarray, cos1: np.ndarray) -> np.ndarray:
    """The angle ``(T,)`` to turn the shin ``u2`` about the unit axis ``n`` so that ``u1 . u2`` becomes
    ``cos1`` (exactly, for an axis off the leg's plane too: ``p + A cos x + B sin x = cos1``); the root
    that bends the knee about ``n`` the usual way (for the plane's normal: new bend minus old bend)."""
    p = np.sum(u1 * n, axis=1) * np.sum(u2 * n, axis=1)
    A = np.sum(u1 * u2, axis=1) - p
    B = np.sum(u1 * _cross(n, u2), axis=1)
    r = np.hypot(A, B)
    return np.arctan2(B, A) + np.arccos(np.clip((cos1 - p) / np.maximum(r, 1e-300), -1.0, 1.0))


def _weights(contacts: Contacts, n_blend: int) -> np.ndarray:
    """Hold weights ``(T, C)`` of every contact joint: 1 in contact, smoothstep ramps around."""
    return np.stack([_hold_weights(m, n_blend) for m in contacts.mask.T], axis=1)


def _root_shift(W: ChainArray, contacts: Contacts, n_blend: int, period: int | None,
                turn: float = 0.0, turn_axis: np.ndarray | None = None) -> np.ndarray:
    """Horizontal world displacement ``(T, 3)`` of the root that cancels the hold-weighted mean horizontal
    velocity of the planted contact joints (the hips follow the planted foot, as in a real stance), less
    its mean over a period (or the take) so the travel is kept; centred on the take.

    For a loop (``period``, the motion at least three periods long) the displacement is the middle period's,
    repeated, and turned with the loop (``turn`` rad per period about ``turn_axis``, default the vertical):
    the velocities are read in a frame turning with the loop and the displacement is turned back, so each
    repeat's is the one before turned, as every other pose of a turning loop is, and a contact across the
    seam is held at the same place seen from either side.  It is 0 at each period's first frame."""
    T = W.shape[0]
    if T < 2:
        return np.zeros((T, 3))
    up = contacts.up
    w = _weights(contacts, n_blend)
    v = np.diff(W[:, list(contacts.joints)], axis=0)                  # (T-1, C, 3)
    v = v - along(v, up)[..., None] * up
    ws = 0.5 * (w[1:] + w[:-1])
    u = -np.einsum("tc,tci->ti", ws, v) / np.maximum(ws.sum(axis=1), 1.0)[:, None]
    if not (period and T >= 3 * period):
        u -= u.mean(axis=0)
        shift = np.vstack([np.zeros(3), np.cumsum(u, axis=0)])
        return shift - shift.mean(axis=0)
    axis = up if turn_axis is None else np.asarray(turn_axis, dtype=np.float64)
    steps = np.arange(period, 2 * period)
    # each step's velocity in the loop's frame at the step's middle (the identity for a straight loop)
    u = np.einsum("tji,tj->ti", axis_rotations(axis, turn * (steps + 0.5) / period), u[steps])
    u -= u.mean(axis=0)
    # (period, 3), 0 at each period's first frame: the loop's first frame keeps its place, and a turning
    # loop turns about it (Cycle.repeat), so the repeats still meet
    s = np.vstack([np.zeros(3), np.cumsum(u[:-1], axis=0)])
    t = np.arange(T)
    return np.einsum("tij,tj->ti", axis_rotations(axis, turn * t / period), s[t % period])


def _descendants(motion: Motion, joint: int) -> np.ndarray:
    """``(J,)`` True for ``joint`` and every joint below it."""
    parents = motion.skeleton.parents
    below = np.zeros(motion.n_joints, bool)
    below[joint] = True
    for j in range(joint + 1, motion.n_joints):
        below[j] = parents[j] >= 0 and below[parents[j]]
    return below


def _leg_ik(motion: Motion, foot, W, Rb: np.ndarray, column: dict, t: np.ndarray, rb: np.ndarray,
            g: np.ndarray, gt: np.ndarray | None, axis: np.ndarray) -> list[tuple[np.ndarray, int, np.ndarray]]:
    """Two-bone IK of one leg at the frames ``t`` (their rows ``rb`` in ``Rb``, the chain's world rotations
    ``(n, len(chain), 3, 3)``, columns as ``column`` says): the ankle to its goal ``g[t]``, the foot turned to
    its toe goal ``gt[t]``, the knee bent about ``axis`` when straight (:func:`_bend_normals`).
    ``[(t, joint, new local quaternions (len(t), 4)), ...]`` for the hip, knee and ankle, each with the sign
    of the old one."""
    skel = motion.skeleton
    H, K, A, l1, l2, u1, u2 = _thigh_shin(W, foot, t)
    G = g[t]
    n = _bend_normals(Rb[rb, column[foot.hip]], u1, u2, axis)
    d = np.clip(_norms(G - H), np.abs(l1 - l2) + 1e-9 * (l1 + l2), (1 - 1e-12) * (l1 + l2))
    cos1 = -np.clip((l1 ** 2 + l2 ** 2 - d ** 2) / (2 * l1 * l2), -1.0, 1.0)  # thigh . shin wanted
    R1 = Rotation.from_rotvec(n * _knee_turn(u1, u2, n, cos1)[:, None]).as_matrix()  # knee bend, world
    A1 = K + np.einsum("tij,tj->ti", R1, A - K)
    size = t.size
    if gt is None:
        R2 = _swing(A1 - H, G - H)                                         # thigh swing about the hip
        aim = np.broadcast_to(np.eye(3), (size, 3, 3))
    else:  # the thigh's swing and the foot's aim at its toe goal, from one scipy Rotation
        swings = _swing(np.concatenate([A1 - H, W[t, foot.toe] - A]), np.concatenate([G - H, gt[t] - G]))
        R2, aim = swings[:size], swings[size:]
    hp, kp, ap = (int(skel.parents[j]) for j in (foot.hip, foot.knee, foot.ankle))
    Rp_hip = Rb[rb, column[hp]] if hp >= 0 else np.broadcast_to(np.eye(3), (size, 3, 3))
    new_parent = R2 @ R1 @ Rb[rb, column[ap]]
    joints = (foot.hip, foot.knee, foot.ankle)
    local = np.concatenate([np.swapaxes(Rp_hip, 1, 2) @ R2 @ Rb[rb, column[foot.hip]],
                            np.swapaxes(Rb[rb, column[kp]], 1, 2) @ R1 @ Rb[rb, column[foot.knee]],
                            np.swapaxes(new_parent, 1, 2) @ aim @ Rb[rb, column[foot.ankle]]])
    quats = Rotation.from_matrix(local).as_quat().reshape(3, size, 4)   # the three joints' from one Rotation
    old = np.swapaxes(motion.rotations[t][:, list(joints)], 0, 1)     # (3, size, 4)
    quats *= np.where(np.sum(quats * old, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    return [(t, j, q) for j, q in zip(joints, quats, strict=True)]


def _bend_axes(feet, W, blocks, column: dict, solved: list[np.ndarray]) -> list[np.ndarray | None]:
    """Each leg's usual bend axis (:func:`_bend_axis`) over all its ``solved`` frames, from the chain's world
    rotations ``blocks`` (``(rows, (n, len(chain), 3, 3))``) a block at a time; the rows are kept and summed at
    once, the same sum as over one array (``None``: a leg with no solved frame)."""
    bends = [np.empty((t.size, 3)) for t in solved]
    thighs = [np.empty((t.size, 3)) for t in solved]
    for rows, Rb in blocks:
        for foot, t, bend, thigh in zip(feet, solved, bends, thighs, strict=True):
            i, k = np.searchsorted(t, rows.start), np.searchsorted(t, rows.stop)
            if k > i:
                _, _, _, _, _, u1, u2 = _thigh_shin(W, foot, t[i:k])
                Rh = Rb[t[i:k] - rows.start, column[foot.hip]]
                bend[i:k] = np.einsum("tji,tj->ti", Rh, _cross(u1, u2))
                thigh[i:k] = np.einsum("tji,tj->ti", Rh, u1)
    return [_bend_axis(bend, thigh) if len(bend) else None for bend, thigh in zip(bends, thighs, strict=True)]


def _solve_legs(motion: Motion, feet, W, blocks, column: dict, solved, goals, toe_goals, axes, moves):
    """The two-bone IK of every leg (:func:`_leg_ik`) at its ``solved`` frames and the travel joint's world
    ``moves`` (``(T, 3)`` each) in its parent's frame, a block of the chain's world rotations at a time:
    ``(new quaternions [(frames, joint, (n, 4)), ...], local moves [(T, 3), ...])``."""
    parent = int(motion.skeleton.parents[motion.travel_joint])
    local_moves = [m if parent < 0 else np.empty_like(m) for m in moves]
    new_quats = []
    for rows, Rb in blocks:
        if parent >= 0:
            for m, local in zip(moves, local_moves, strict=True):
                local[rows] = np.einsum("tji,tj->ti", Rb[:, column[parent]], m[rows])
        for foot, g, gt, t, axis in zip(feet, goals, toe_goals, solved, axes, strict=True):
            t = t[np.searchsorted(t, rows.start):np.searchsorted(t, rows.stop)]
            if t.size:
                new_quats += _leg_ik(motion, foot, W, Rb, column, t, t - rows.start, g, gt, axis)
    return new_quats, local_moves


def lock_feet(motion: Motion, contacts: Contacts, *, blend: float = BLEND_SECONDS, reach: float = REACH,
              follow: bool = True, period: int | None = None, frames: slice | None = None,
              clearance: float | np.ndarray | None = None, transforms: tuple | None = None,
              turn: float = 0.0, turn_axis: np.ndarray | None = None, hand_over: bool = False) -> Motion:
    """``motion`` with every contact of ``contacts`` held still (the method of the module docstring).

    ``blend``: seconds of cross-fade before and after each contact; ``reach``: fraction of a leg's length
    beyond which the root is lowered; ``follow``: first move the root horizontally with the planted feet;
    ``period``: the motion is a loop repeated every ``period`` frames (at least three times), so the root
    correction keeps the travel of each period; ``frames``: solve and return only these frames (the rest
    is context: the frames of a loop's repeat that are read back); ``clearance``: the fraction of the body
    height a swinging foot clears, one for all contact joints or ``(C,)`` one per joint of ``contacts``
    (0: no swing clearance; default: the motion's own, :func:`~mocycle.contacts.clearance.swing_clearance`);
    ``transforms``: ``chain_transforms(motion, chain_joints(motion, legs))`` when the caller has them (they are
    changed in place; without them the legs' world positions are held and their rotations made a block of
    frames at a time); ``turn``: with ``period``, the loop's turn per period (rad about ``turn_axis``, default
    the vertical: each repeat is the one before turned, as :meth:`~mocycle.cycle.Cycle.repeat` makes them);
    ``hand_over``: the caller gives ``motion`` up, and the result is made from its arrays instead of copies
    (:meth:`~mocycle.motion.Motion.hand_over`: ``motion`` is emptied; a long take is locked without a
    second copy of it).  Returns a new Motion with the same skeleton and frame time.
    """
    if contacts.n_frames != motion.n_frames:
        raise ValueError(f"contacts cover {contacts.n_frames} frames, the motion {motion.n_frames}")
    n_blend = max(1, int(round(blend / motion.frame_time)))
    if clearance is None:
        clearance = swing_clearance(motion, contacts.feet, up=contacts.up, body=contacts.body)
    clearance = np.broadcast_to(np.asarray(clearance, dtype=np.float64), (len(contacts.joints),))
    skel = motion.skeleton
    chain = chain_joints(motion, leg_joints(contacts.feet))
    below = _descendants(motion, motion.travel_joint)
    W = chain_positions(motion, chain) if transforms is None else transforms[1]
    moves = []  # (T, 3) world-frame moves of the travel joint (and all below it), in the order they are made
    if follow:
        shift = _root_shift(W, contacts, n_blend, period, turn, turn_axis)
        if np.abs(shift).max() > 0:
            moves.append(shift)
            W.add(below, shift)    # the travel joint and all below it move with it; no rotation changes
    n_extend = int(round(EXTEND_SECONDS / motion.frame_time))
    n_bridge = int(round(BRIDGE_SECONDS / motion.frame_time))
    goals, toe_goals, held, changed = [], [], [], []
    reaches = [_reach(W, foot, reach) for foot in contacts.feet]   # of the legs followed, before any lowering
    for f in range(len(contacts.feet)):
        g, gt, h, ch = _foot_goals(W, contacts, f, n_extend, n_bridge, n_blend, reaches[f], clearance)
        goals.append(g)
        toe_goals.append(gt)
        held.append(h)
        changed.append(ch)
    delta = _lowering(W, contacts, goals, held, reaches, n_blend)
    lowered = delta > 0
    if lowered.any():  # every foot keeps its goal in the world: a swing foot does not dip with the root
        down = -np.outer(delta, contacts.up)
        moves.append(down)
        W.add(below, down)
    for foot, g, h in zip(contacts.feet, goals, held, strict=True):  # goals not held: within reach, softly
        free = ~h
        base, hips = W[free, foot.ankle], W[free, foot.hip]
        R, zone = _reach(W, foot, reach)[free], SOFT_ZONE * _leg_length(W, foot)[free]
        corr = g[free] - base
        out = _soft_reach(base, corr, hips, R, zone, contacts.up)
        # next to a held frame (whose goal is within the reach, the root lowered or the heel lifted for it) the
        # goal is held within the reach as there and eased to the soft one over the blend: a leg leaving a
        # hold near straight (a toe-off) is not bent by the soft zone in one frame
        ease = _smoothstep(_frames_from(h)[free] / (n_blend + 1))
        m = ease < 1.0
        if m.any():
            hard = _soft_reach(base[m], corr[m], hips[m], R[m], 1e-6 * zone[m], contacts.up)
            out[m] = hard + ease[m, None] * (out[m] - hard)
        g[free] = base + out
    window = np.zeros(motion.n_frames, bool)
    window[frames if frames is not None else slice(None)] = True
    solved = [np.flatnonzero((ch | lowered) & window) for ch in changed]  # the frames each leg's IK changes
    travel = motion.travel_joint

    def blocks():  # the chain's world rotations (n, len(chain), 3, 3) of the frames ``rows``, a block at a time
        if transforms is not None:
            return [(slice(0, motion.n_frames), transforms[0].data)]
        return chain_rotation_blocks(motion, chain)

    column = {j: i for i, j in enumerate(chain)}
    axes = _bend_axes(contacts.feet, W, blocks(), column, solved)
    new_quats, local_moves = _solve_legs(motion, contacts.feet, W, blocks(), column, solved, goals, toe_goals, axes,
                                         moves)
    del W  # the chain's world positions and rotations: not needed for the quaternions (memory)
    T, frame_time = motion.n_frames, motion.frame_time
    if hand_over:
        rotations, static, tracks = motion.hand_over()
    else:  # the input's tracks are shared (read-only), the travel joint's copied when it moves
        rotations, static = motion.rotations.copy(), motion.translations_at(0)
        tracks = motion.tracks
    if local_moves:
        path = tracks.get(travel, np.broadcast_to(static[travel], (T, 3)))
        path = path if path.flags.writeable else path.copy()
        for local in local_moves:
            path += local
        tracks[travel] = path
    row = np.arange(len(window))  # a frame's row in the output
    if frames is not None:
        row = np.full(len(window), -1)
        row[frames] = np.arange(window.sum())
        rotations = rotations[frames].copy()
        tracks = {j: track[frames].copy() for j, track in tracks.items()}
    for t, j, quats in new_quats:  # frames and joints not touched keep their exact quaternions
        rotations[row[t], j] = quats
    del new_quats
    return Motion(skel, rotations, static, frame_time, tracks=tracks, copy=False)
