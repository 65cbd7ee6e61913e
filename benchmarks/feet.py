"""Feet that stay planted: foot locking on the loops of every walk and run in ../shared/data.

    python benchmarks/feet.py [--quick] [--data DIR] [--bend DEG] [--fps FPS]

Per take: a harmonic M1 cycle with its root motion (``extract_cycle`` as
``mocycle loop`` runs it), then :func:`mocycle.cycle.lock_cycle`.  Printed,
input vs output:

* skate (units/s, :func:`mocycle.contacts.skate`) of the input's excited
  frames, of the fitted cycle repeated twice with its root motion, and of the
  cleaned cycle repeated twice; the cleaned over the input's;
* the largest frame-to-frame change of any leg joint's local rotation (rad)
  before and after clean-up (a knee pop shows here);
* foot jumps: frames of the loop (played round) where an ankle or toe jumps
  vertically in one frame (:func:`mocycle.contacts.foot_jumps`), fitted and
  cleaned (a held toe let go by its heel shows here, not in the leg step);
* bone lengths: the largest change of any joint-to-parent distance (joints
  whose translation is constant), in file units;
* the planted feet: the largest movement of a contact joint during its
  contacts after clean-up (file units), in the locked take ("planted") and in
  the cleaned loop repeated three times with its root motion, contacts over
  a seam included ("held"); "turn": the loop's turn per cycle (degrees);
* the seam: the largest leg-joint rotation step across the wrap of the loop
  over the largest step inside it, for the fitted and the cleaned loop;
* seconds: ``extract_cycle`` and ``lock_cycle``; and the share of the feet part in the whole loop task
  (``tasks.loop.run``, what ``mocycle loop --root motion`` runs: read, phase, fit, feet, metrics, checks).

Then blends (``blend_cycles`` of the Bandai normal walk with each other Bandai
walk, equal weights, locked as ``mocycle blend --root motion`` does): skate of
the two captured takes (mean), of the blend and of the locked blend; leg steps.

Then stretched takes (``stretch_motion`` by 2 of every Bandai walk and the
cmu-iclone walks, locked as ``mocycle stretch`` does): skate of the take, of
the stretched take and of the locked one; leg steps.

Goals (issue 13): median skate of the cleaned loops <= 0.5x the input's and no
take worse than its input; leg step after <= 1.5x before; bone lengths exact
(1e-9); clean-up <= 20 % of the loop job.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

from mocycle.contacts import detect_contacts, foot_jumps, largest_leg_step, lock_feet, ranges
from mocycle.contacts import skate as skate_measure
from mocycle.contacts.skate import leg_joints
from mocycle.cycle import extract_cycle, lock_cycle
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.tasks import loop as loop_task

LOCK: dict = {}  # options of lock_cycle / lock_feet (--clearance)
SKATE: dict = {}  # options of the skate measure (--skate-height)


def skate(motion, *args, **kw):
    return skate_measure(motion, *args, **SKATE, **kw)


ICLONE = ("02_01", "02_02", "02_03", "05_01") + tuple(f"07_{i:02d}" for i in range(1, 13))


def takes(data: Path, quick: bool) -> list[Path]:
    bandai = sorted((data / "bandai").glob("dataset-1_*.bvh"))
    bandai = [p for p in bandai if any(k in p.name for k in ("_walk_", "_run_", "_dash_"))]
    iclone = [data / "cmu-iclone" / f"{n}.bvh" for n in ICLONE]
    files = [p for p in bandai + iclone if p.exists()]
    return files[::8] if quick else files


def bone_error(a, b) -> float:
    skel = a.skeleton
    moving = np.ptp(a.translations, axis=0).max(axis=1) > 1e-9
    fixed = [j for j in range(1, skel.n_joints) if not moving[j]]
    Wa, Wb = a.world_positions(), b.world_positions()
    par = skel.parents[fixed]
    la = np.linalg.norm(Wa[:, fixed] - Wa[:, par], axis=-1)
    lb = np.linalg.norm(Wb[:, fixed] - Wb[:, par], axis=-1)
    return float(np.abs(la - lb).max())


def bend(motion, degrees: float):
    """``motion`` turning: its travel joint's path laid on a circle (``degrees`` of turn per body height of
    travel) and the body turned with it, so that a straight walk becomes a turning one whose planted feet
    stay nearly planted (a foot ahead of the hips is off the circle by its distance² / (2 × radius))."""
    from scipy.spatial.transform import Rotation

    from mocycle.contacts import body_height, up_axis

    up = up_axis(motion)
    j = motion.travel_joint
    root = motion.translations[:, j]
    d = root[-1] - root[0]
    d = d - (d @ up) * up
    f = d / np.linalg.norm(d)
    side = np.cross(up, f)
    rel = root - root[0]
    s, lat, h = rel @ f, rel @ side, rel @ up
    k = np.radians(degrees) / body_height(motion, up)
    phi = k * s
    t = motion.translations.copy()
    t[:, j] = (root[0] + np.outer(np.sin(phi) / k - lat * np.sin(phi), f)
               + np.outer((1 - np.cos(phi)) / k + lat * np.cos(phi), side) + np.outer(h, up))
    q = motion.rotations.copy()
    q[:, j] = (Rotation.from_rotvec(np.outer(phi, up)) * Rotation.from_quat(q[:, j])).as_quat()
    return motion.replace(rotations=q, translations=t)


def held_across_seams(cleaned, contacts) -> float:
    """The largest movement of a contact joint during its contacts in the cleaned loop repeated three times
    with its root motion (contacts over a seam included: the repeats must meet, turning or not)."""
    W = cleaned.repeat(3, root="motion").world_positions()
    worst = 0.0
    for c, j in enumerate(contacts.joints):
        for s, e in ranges(np.tile(contacts.mask[:, c], 3)):
            worst = max(worst, float(np.abs(W[s:e, j] - W[s, j]).max()))
    return worst


def planted(motion, contacts) -> float:
    W = motion.world_positions()
    worst = 0.0
    for c, j in enumerate(contacts.joints):
        for s, e in ranges(contacts.mask[:, c]):
            worst = max(worst, float(np.abs(W[s:e, j] - W[s, j]).max()))
    return worst


def fast_share(motion) -> float:
    """The share of ``motion``'s skate from frame steps where the joint moves faster than one body height per
    second: a swing foot passing low, or a heel landing at speed, not a planted foot gliding."""
    from mocycle.contacts import body_height, find_feet, up_axis
    from mocycle.contacts.skate import SKATE_HEIGHT

    up = up_axis(motion)
    body = body_height(motion, up)
    joints = [j for f in find_feet(motion.skeleton) for j in f.contact_joints]
    P = motion.world_positions()[:, joints]
    h = P @ up
    h = h - h.min(axis=0)
    step = np.diff(P, axis=0)
    speed = np.linalg.norm(step - (step @ up)[..., None] * up, axis=-1) / motion.frame_time
    hm = 0.5 * (h[1:] + h[:-1])
    H = SKATE_HEIGHT * body
    c = np.where(hm < H, 2.0 - 2.0 ** (hm / H), 0.0) * speed
    return float(c[speed > body].sum() / max(c.sum(), 1e-300))


def seam_ratio(cycle, feet) -> float:
    m = cycle.repeat(2, root="inplace")
    q = m.rotations[:, leg_joints(feet)]
    steps = 2 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], axis=-1)), 0, 1)).max(axis=1)
    n = cycle.n_frames
    return float(steps[n - 1] / max(np.delete(steps, n - 1).max(), 1e-12))


def blends(data: Path, quick: bool) -> list[dict]:
    from mocycle.cycle import blend_cycles

    walks = sorted((data / "bandai").glob("dataset-1_walk_*.bvh"))
    base = data / "bandai" / "dataset-1_walk_normal_001.bvh"
    others = [p for p in walks if p != base][:: 4 if quick else 1]
    if not base.exists():
        return []
    rows = []
    print(f"\n{'blend of walk_normal with':34s} {'skate in':>8s} {'blend':>7s} {'locked':>7s} {'lock/in':>7s} "
          f"{'step before':>11s} {'after':>6s} {'lock s':>7s}")
    a = read(base)
    for path in others:
        b = read(path)
        try:
            blend = blend_cycles([a, b])
        except MocycleError as exc:
            print(f"{path.name:34s} no blend: {exc}")
            continue
        t0 = time.perf_counter()
        cleaned, _ = lock_cycle(blend.cycle, reference=[a, b], **LOCK)
        t_lock = time.perf_counter() - t0
        s_in = float(np.mean([skate(a), skate(b)]))  # the two captures
        before, after = blend.cycle.repeat(2, root="motion"), cleaned.repeat(2, root="motion")
        row = dict(take=path.name, s_in=s_in, s_fit=skate(before), s_out=skate(after),
                   step_before=largest_leg_step(before), step_after=largest_leg_step(after))
        row["ratio"] = row["s_out"] / s_in
        rows.append(row)
        print(f"{path.name:34s} {s_in:8.2f} {row['s_fit']:7.2f} {row['s_out']:7.2f} {row['ratio']:7.2f} "
              f"{row['step_before']:11.3f} {row['step_after']:6.3f} {t_lock:7.3f}")
    if rows:
        worst = max(rows, key=lambda r: r["ratio"])
        print(f"blends: median locked/input {statistics.median(r['ratio'] for r in rows):.2f} (goal <= 0.5), worst "
              f"{worst['ratio']:.2f} ({worst['take']}); "
              f"locked above input: {sum(r['s_out'] > r['s_in'] for r in rows)} of {len(rows)}; leg step > 1.5x "
              f"before: {sum(r['step_after'] > 1.5 * r['step_before'] for r in rows)}")
    return rows


def stretched(data: Path, quick: bool) -> list[dict]:
    from mocycle.warp import stretch_motion

    files = [p for p in takes(data, quick) if "_walk_" in p.name or p.name.startswith("07_")]
    rows = []
    print(f"\n{'stretched x2':34s} {'skate in':>8s} {'stretch':>7s} {'locked':>7s} {'lock/in':>7s} "
          f"{'step before':>11s} {'after':>6s} {'lock s':>7s}")
    for path in files:
        motion = read(path)
        try:
            long, _ = stretch_motion(motion, 2.0)
        except MocycleError as exc:
            print(f"{path.name:34s} no stretch: {exc}")
            continue
        t0 = time.perf_counter()
        locked = lock_feet(long, detect_contacts(long), **LOCK)
        t_lock = time.perf_counter() - t0
        row = dict(take=path.name, s_in=skate(motion), s_fit=skate(long), s_out=skate(locked),
                   step_before=largest_leg_step(long), step_after=largest_leg_step(locked))
        row["ratio"] = row["s_out"] / row["s_in"]
        rows.append(row)
        print(f"{path.name:34s} {row['s_in']:8.2f} {row['s_fit']:7.2f} {row['s_out']:7.2f} {row['ratio']:7.2f} "
              f"{row['step_before']:11.3f} {row['step_after']:6.3f} {t_lock:7.3f}")
    if rows:
        worst = max(rows, key=lambda r: r["ratio"])
        print(f"stretched: median locked/input {statistics.median(r['ratio'] for r in rows):.2f} (goal <= 0.5), worst "
              f"{worst['ratio']:.2f} ({worst['take']}); "
              f"locked above input: {sum(r['s_out'] > r['s_in'] for r in rows)} of {len(rows)}; leg step > 1.5x "
              f"before: {sum(r['step_after'] > 1.5 * r['step_before'] for r in rows)}")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--part", choices=("all", "loops", "blends", "stretch"), default="all")
    ap.add_argument("--clearance", type=float, default=None,
                    help="one swing clearance for every foot, fraction of the body height (default: each take's "
                         "own, contacts.clearance.swing_clearance; 0: off)")
    ap.add_argument("--skate-height", type=float, default=None,
                    help="H of the skate measure, fraction of the body height (default 0.015, the issue's)")
    ap.add_argument("--bend", type=float, default=0.0,
                    help="loops of turning walks: each take's path bent onto a circle, DEG degrees of turn per body "
                         "height of travel (the body turned with it), before its loop is made")
    ap.add_argument("--fps", type=float, default=None,
                    help="loops of the takes resampled to this rate first (a capture day's 120 fps: a foot's jump "
                         "of a frame is a jump there)")
    ap.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[1].parent / "shared" / "data")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    if args.clearance is not None:
        global LOCK
        LOCK = {"clearance": args.clearance}
        print(f"swing clearance: {args.clearance} of the body height")
    if args.skate_height is not None:
        SKATE["height"] = args.skate_height
        print(f"skate measure's H: {args.skate_height} of the body height")
    if args.part in ("all", "loops"):
        loops(args)
    if args.part in ("all", "blends"):
        blends(args.data, args.quick)
    if args.part in ("all", "stretch"):
        stretched(args.data, args.quick)


def loops(args) -> None:
    rows = []
    print(f"{'take':34s} {'skate in':>8s} {'fitted':>7s} {'locked':>7s} {'lock/in':>7s} {'step before':>11s} "
          f"{'after':>6s} {'jumps':>5s} {'bones':>8s} {'planted':>8s} {'held':>8s} {'turn':>5s} {'seam':>5s} "
          f"{'fit':>5s} "
          f"{'loop s':>7s} {'lock s':>7s}")
    for path in takes(args.data, args.quick):
        motion = read(path)
        if args.fps:
            motion = motion.resample(args.fps)
        if args.bend:
            motion = bend(motion, args.bend)
        t0 = time.perf_counter()
        try:
            cycle = extract_cycle(motion)
        except MocycleError as exc:
            print(f"{path.name:34s} no loop: {exc}")
            continue
        t1 = time.perf_counter()
        frames = cycle.axis.frames()
        cleaned, contacts = lock_cycle(cycle, reference=motion[frames[0]:frames[-1] + 1], **LOCK)
        t2 = time.perf_counter()
        s_in = skate(motion[frames[0]:frames[-1] + 1])
        before, after = cycle.repeat(2, root="motion"), cleaned.repeat(2, root="motion")
        s_fit, s_out = skate(before), skate(after)
        ext = cycle.repeat(3, root="motion")
        con = detect_contacts(ext)
        locked = lock_feet(ext, con, **LOCK)  # bones and held feet checked on the whole repeated take
        job = loop_task.run(motion if args.bend or args.fps else path,  # what `mocycle loop` runs
                            loop_task.Options(root="motion"))
        row = dict(take=path.name, s_in=s_in, s_fit=s_fit, s_out=s_out, ratio=s_out / s_in,
                   t_job=job.timings_s["total"], t_job_feet=job.timings_s.get("feet", 0.0),
                   fast=fast_share(motion[frames[0]:frames[-1] + 1]),
                   step_before=largest_leg_step(before), step_after=largest_leg_step(after),
                   jumps_fit=len(foot_jumps(cycle.repeat(1, root="motion"), contacts.feet, wrap=True)),
                   jumps=len(foot_jumps(cleaned.repeat(1, root="motion"), contacts.feet, wrap=True)),
                   bones=bone_error(ext, locked), planted=planted(locked, con),
                   held=held_across_seams(cleaned, contacts),
                   turn=float(np.degrees(cycle.drift[3])), seam=seam_ratio(cleaned, contacts.feet),
                   seam_fit=seam_ratio(cycle, contacts.feet),
                   t_loop=t1 - t0, t_lock=t2 - t1)
        rows.append(row)
        print(f"{path.name:34s} {s_in:8.2f} {s_fit:7.2f} {s_out:7.2f} {row['ratio']:7.2f} "
              f"{row['step_before']:11.3f} {row['step_after']:6.3f} {row['jumps']:5d} {row['bones']:8.1e} "
              f"{row['planted']:8.1e} "
              f"{row['held']:8.1e} {row['turn']:5.1f} {row['seam']:5.2f} {row['seam_fit']:5.2f} {row['t_loop']:7.2f} "
              f"{row['t_lock']:7.3f}")
    if not rows:
        return
    ratios = [r["ratio"] for r in rows]
    worse = [r["take"] for r in rows if r["s_out"] > r["s_in"]]
    pops = [r["take"] for r in rows if r["step_after"] > 1.5 * r["step_before"]]
    share = sum(r["t_lock"] for r in rows) / sum(r["t_loop"] + r["t_lock"] for r in rows)
    print()
    print(f"takes: {len(rows)}")
    print(f"median skate: input {statistics.median(r['s_in'] for r in rows):.2f}, fitted "
          f"{statistics.median(r['s_fit'] for r in rows):.2f}, locked {statistics.median(r['s_out'] for r in rows):.2f}"
          f" units/s; median locked/input {statistics.median(ratios):.2f} (goal <= 0.5), worst {max(ratios):.2f} "
          f"({max(rows, key=lambda r: r['ratio'])['take']})")
    print(f"share of the input's skate from steps faster than 1 body height/s (swing feet passing low, heels "
          f"landing at speed; not a planted foot): median {statistics.median(r['fast'] for r in rows):.0%}")
    print(f"takes whose locked loop skates more than the input: {len(worse)} (goal 0) {' '.join(worse[:12])}")
    print(f"takes with a leg step > 1.5x before: {len(pops)} (goal 0) {' '.join(pops[:12])}")
    jumped = [r["take"] for r in rows if r["jumps"]]
    print(f"foot jumps of one frame: fitted loops {sum(r['jumps_fit'] for r in rows)}, cleaned "
          f"{sum(r['jumps'] for r in rows)} in {len(jumped)} loops {' '.join(jumped[:12])}")
    print(f"largest bone-length change: {max(r['bones'] for r in rows):.1e} (goal 1e-9); largest contact-joint "
          f"movement during a contact: {max(r['planted'] for r in rows):.1e}; in the loop repeated 3 times, seams "
          f"included: {max(r['held'] for r in rows):.1e} (largest turn per cycle "
          f"{max(abs(r['turn']) for r in rows):.1f} deg)")
    print(f"largest seam step / largest inner step: cleaned loops {max(r['seam'] for r in rows):.2f}, fitted loops "
          f"{max(r['seam_fit'] for r in rows):.2f}; cleaned above 1.1x its fitted loop's: "
          f"{sum(r['seam'] > 1.1 * max(r['seam_fit'], 1.0) for r in rows)}")
    job_share = sum(r["t_job_feet"] for r in rows) / sum(r["t_job"] for r in rows)
    print(f"clean-up time / loop job time: {share:.1%} against extract_cycle alone; {job_share:.1%} of the whole "
          f"loop task (tasks.loop.run, read to metrics; goal <= 20%)")


if __name__ == "__main__":
    main()
