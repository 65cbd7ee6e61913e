"""The loop as the review shows it beside the take: phase-aligned, repeated with root motion, placed at the take.

:func:`loop_view` reads the loop task's own results (no new analysis): the cycle's ``positions`` (where each
frame of the take falls in the cycle, from the phase), the library's ``Cycle.repeat`` (each repeat moved on by
the travel and turn per cycle) and the cycle space's ``encode``/``decode`` (root path and heading as ``L``).
"""

from __future__ import annotations

import numpy as np

from ..cycle.representation import BLOCK_FRAMES
from ..motion import Motion
from ..rotations import axis_rotations, continuous_quats


def loop_offset(report, role: str = "loop") -> int:
    """The take frame where the motion a loop was fitted on starts (a part of the take: its first frame; 0
    when the whole take was looped)."""
    return int((report.extras.get(role) or {}).get("offset", 0))


def take_phase(report, role: str = "loop") -> list:
    """The loop's phase at every frame of the take (``report.motions["input"]``), rounded, ``None`` outside
    the part it was fitted on (JSON has no NaN)."""
    coords = np.asarray(report.result.periodic.coords, dtype=np.float64)
    T, at = report.motions["input"].n_frames, loop_offset(report, role)
    out: list = [None] * T
    for k, v in enumerate(coords[: max(0, T - at)]):
        out[at + k] = round(float(v), 4)
    return out


def strip_parts(report) -> list[dict]:
    """The take's parts for the phase strip: frames (the input's), kind, whether it loops."""
    start = report.facts.get("first_frame", 0)
    return [{"frames": [p["frames"][0] - start, p["frames"][1] - start], "kind": p["kind"], "loop": p["loop"]}
            for p in report.facts.get("parts", [])]


def strip_excitation(report) -> list[list[int]]:
    """The loop's excited regions in the input's frames (the facts give them in the take's)."""
    start = report.facts.get("first_frame", 0)
    return [[a - start, b - start] for a, b in report.facts.get("excitation", [])]


def cycle_frames(cycle, n_frames: int, offset: int = 0) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """Where each of the take's ``n_frames`` frames falls in the repeated cycle: ``(u, segments)``.

    ``u (T,)``: cycle frames, unwrapped within each excited region (``u mod N`` is the cycle frame whose
    phase is the take's at that frame, from ``cycle.positions``); outside the regions the count goes on at
    the loop's own rate (``N / period_frames`` cycle frames per frame) from the nearest region before (or,
    before the first region, back from it).  ``segments``: ``(start, stop, anchor)`` frame ranges, one per
    excited region, ``anchor`` its first frame: where the loop is placed at the take.  ``offset``: the take
    frame where the motion the cycle was fitted on starts (a part of the take)."""
    N = cycle.n_frames
    regions = [(s + offset, e + offset) for s, e in cycle.axis.regions]
    if len(cycle.positions) != sum(e - s for s, e in regions) or regions[-1][1] > n_frames:
        raise ValueError(f"the cycle's positions ({len(cycle.positions)}) do not cover its excited regions "
                         f"{regions} of a {n_frames}-frame take")
    u = np.full(n_frames, np.nan)
    at = 0
    for s, e in regions:
        pos = np.asarray(cycle.positions[at: at + (e - s)], dtype=np.float64)
        at += e - s
        u[s:e] = np.unwrap(pos * (2 * np.pi / N)) * (N / (2 * np.pi))
    rate = N / cycle.period_frames
    segments = []
    for i, (s, e) in enumerate(regions):
        start = 0 if i == 0 else s
        stop = regions[i + 1][0] if i + 1 < len(regions) else n_frames
        u[start:s] = u[s] - (s - np.arange(start, s)) * rate
        u[e:stop] = u[e - 1] + (np.arange(e, stop) - (e - 1)) * rate
        segments.append((start, stop, s))
    return u, segments


def loop_view(report):
    """The loop of a ``tasks.loop`` report as a Motion with the take's frames: frame ``f`` is the cycle frame
    whose phase matches the take's at ``f`` (linear between cycle frames), in the pass of the cycle repeated
    (``report.facts["root"]``: ``motion`` moves on by the travel and turn per cycle as ``Cycle.repeat``
    does).  Placement: at each excited region's first frame the loop's travel joint is put where the take's
    is along the floor and turned to its heading; ``inplace`` loops follow the take's travel joint along the
    floor every frame.  Returns ``(motion, facts)``, facts with ``loop_frame`` (``u mod N`` per frame) and
    ``segments``."""
    take, cycle, root = report.motions["input"], report.result, report.facts["root"]
    space, N, T = cycle.space, cycle.n_frames, report.motions["input"].n_frames
    u, segments = cycle_frames(cycle, T, loop_offset(report))
    index = np.empty(T)
    for start, stop, _ in segments:  # each region's passes counted from the first repeat
        index[start:stop] = u[start:stop] - N * np.floor(u[start:stop].min() / N)
    # the repeated cycle's path from its travel joint alone (no (T, J) rotations of every joint decoded); P
    # repeats every cycle (the repeats differ in L only): one cycle read
    Lv = cycle.repeat_path(int(np.floor(index.max() / N)) + 2, root=root)
    Pv = space.encode(cycle.repeat(2, root=root)[: N + 1])[0]
    i0 = np.floor(index).astype(int)
    a = (index - i0)[:, None]
    L = (1 - a) * Lv[i0] + a * Lv[i0 + 1]
    Lt = space.path(take)
    up = space.up
    for start, stop, anchor in segments:
        turn = Lt[anchor, 3] - L[anchor, 3]
        R = axis_rotations(up, np.array([turn]))[0]
        pivot = L[anchor, :3].copy()
        move = Lt[anchor, :3] - pivot
        move -= (move @ up) * up  # along the floor: the loop keeps its own height
        L[start:stop, :3] = (L[start:stop, :3] - pivot) @ R.T + pivot + move
        L[start:stop, 3] += turn
    if root == "inplace":
        gap = Lt[:, :3] - L[:, :3]
        L[:, :3] += gap - np.outer(gap @ up, up)
    facts = {"loop_frame": np.round(np.mod(u, N), 3).tolist(), "segments": [list(s) for s in segments],
             "cycle_frames": N, "root": root}
    # the rows of P are interpolated and decoded a block of frames at a time: no (T, 9J) array is held
    quats, tracks = np.empty((T, space.n_joints, 4)), {}
    for f0 in range(0, T, BLOCK_FRAMES):
        f1 = min(T, f0 + BLOCK_FRAMES)
        i, w = i0[f0:f1] % N, a[f0:f1]
        quats[f0:f1], rows = space.decode_rows((1 - w) * Pv[i] + w * Pv[i + 1], L[f0:f1])
        for j, track in rows.items():
            if j not in tracks:  # the same joints in every block: each track is made once
                tracks[j] = np.empty((T, 3))
            tracks[j][f0:f1] = track
    return Motion(space.skeleton, continuous_quats(quats, inplace=True), space.static_translations, space.frame_time,
                  tracks=tracks, copy=False), facts
