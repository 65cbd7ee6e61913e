"""Capture sessions (issue 35): takes joined end to end, every steady part looped, judged by an independent ruler.

    python benchmarks/sessions.py [--quick] [--synthetic-only] [--minutes 1,4,15] [--fps 120] [--keep DIR]

Builds sessions with :func:`mocycle.datasets.join_takes` (each take turned and shifted to start where the last
ended, 10-frame cross-fade; the take's label is the truth of its stretch):

* from the project's generated motions: walks, walk-turn-walks, runs, waves, a dance step on the spot (legs
  moving without landings), one-off gestures and a raised hand, at 30 and 60 fps;
* from ``../shared/data`` (when present): the Bandai "youthful" session of the sessions issue (walk, turn
  right, run, wave, raise a hand, turn left, raise both hands, walk) and the same takes in the issue's own order
  (walk, turn, run, wave, gesture, turn, walk: a turn take that walks out into a walk) at 30 fps and at 120 fps,
  and sessions of ``--minutes`` minutes drawn (seeded) from every Bandai take of that rig (walks, runs, dashes,
  walk-turn-walks, waves, raised hands), resampled to ``--fps``;
* the issue-order session again on a game tool's conventions (Mixamo's joint names, metres, Z up, 60 fps);
* from ``../shared/data/cmu-iclone`` (when present): CMU takes retargeted to the iClone rig at 60 fps (other
  performers, another skeleton, floors that drift within a take), one session per rig the takes come on
  (``CC_Base_Hip``: walks of three subjects, two dance phrases, a run of punches, a jump; ``RL_BoneRoot``: three
  walks and a short jog): takes of different rigs are never joined.

Then runs ``mocycle loop SESSION -o OUT/s.bvh --part all --root motion --json`` as a user would, and prints per
session: stretches, parts found, loops written, the stretches that should get a loop of their own (every gait
stretch of at least 1.5 strides, every wave and dance step) and how many did, loops that span a border (a loop
reaching into a second stretch by more than half its period), loops more than 8 % off the stride period (or the
arms') over their frames or off the turn by more than max(10 deg, 25 %), loopable parts neither looped nor listed
in ``not_looped``, one-off gestures looped, the exit code, CPU seconds and peak memory of the command.

The ruler (``benchmarks/activities.py``'s ``Body``) uses none of mocycle's phase, cycle or contacts code: foot
landings from foot heights and speeds, the heading from the upper legs, the hands' period by autocorrelation.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from activities import Body, default_data, mocycle_cmd  # noqa: E402

import mocycle  # noqa: E402
from mocycle.axes import vertical_axis  # noqa: E402
from mocycle.datasets import (  # noqa: E402
    join_takes,
    synthetic_gesture,
    synthetic_run,
    synthetic_sway,
    synthetic_walk,
    synthetic_walk_turn_walk,
    synthetic_wave,
)

GAIT = ("walk", "run", "turn")          # labels whose stretch is a gait (a loop of its own when >= 1.5 strides)
REPEATS = ("wave", "sway")              # labels whose stretch repeats without gait (a loop of its own)
ONE_OFF = ("gesture", "raise")          # labels never to be looped
PERIOD_TOL = 0.08
CROSSFADE = 10


@dataclass
class Session:
    name: str
    path: Path
    stretches: list[tuple[str, int, int]]
    fps: float
    frames: int


@dataclass
class Result:
    session: Session
    code: int
    cpu_s: float
    wall_s: float
    peak_mb: float
    doc: dict | None
    stderr: str
    rows: dict = field(default_factory=dict)


# -- building sessions -------------------------------------------------------------------------------------------


def synthetic_sessions(folder: Path, quick: bool) -> list[Session]:
    out = []
    for fps in (30, 60) if not quick else (30,):
        takes = [
            ("walk", synthetic_walk(n_frames=6 * fps, fps=fps, period_s=1.0, noise_deg=1.0, seed=1)),
            ("turn", synthetic_walk_turn_walk(2.0, 90.0, 2.0, 2.0, fps=fps, period_s=1.1, noise_deg=1.0, seed=2)),
            ("run", synthetic_run(n_frames=5 * fps, fps=fps, period_s=0.7, noise_deg=1.0, seed=3)),
            ("wave", synthetic_wave(n_frames=5 * fps, fps=fps, hand="right", wave_period_s=0.6, seed=4)),
            ("gesture", synthetic_gesture(n_frames=3 * fps, fps=fps, seed=5)),
            ("sway", synthetic_sway(n_frames=6 * fps, fps=fps, period_s=1.2, seed=6)),
            ("turn", synthetic_walk_turn_walk(2.0, -60.0, 2.0, 2.0, fps=fps, period_s=0.9, noise_deg=1.0, seed=7)),
            ("walk", synthetic_walk(n_frames=5 * fps, fps=fps, period_s=1.2, noise_deg=1.0, seed=8)),
        ]
        out.append(_write(folder, f"synthetic_{fps}fps", takes, None))
    return out


BANDAI_SESSION = [("walk", "dataset-2_walk_youthful_025"), ("turn", "dataset-2_walk-turn-right_youthful_027"),
                  ("run", "dataset-2_run_youthful_019"), ("wave", "dataset-2_wave-both-hands_youthful_026"),
                  ("raise", "dataset-2_raise-up-right-hand_youthful_023"),
                  ("turn", "dataset-2_walk-turn-left_youthful_001"),
                  ("raise", "dataset-2_raise-up-both-hands_youthful_001"), ("walk", "dataset-2_walk_youthful_025")]
#: ... and in the issue's own order (walk, turn, run, wave, gesture, turn, walk): the last turn take walks out of its
#: turn into a walk of the same tempo
BANDAI_ISSUE_ORDER = [item for item in BANDAI_SESSION if item[1] != "dataset-2_raise-up-both-hands_youthful_001"]


def _label(name: str) -> str:
    for key, label in (("walk-turn", "turn"), ("wave", "wave"), ("raise", "raise"), ("dash", "run"),
                       ("run", "run"), ("walk", "walk")):
        if key in name:
            return label
    return "other"


def real_sessions(folder: Path, data: Path, minutes: list[float], fps: float, quick: bool) -> list[Session]:
    files = {p.stem: p for sub in ("bandai", "bandai2") for p in sorted((data / sub).glob("*.bvh"))}
    if not files:
        return []
    out = []
    for stem, order in (("bandai_youthful", BANDAI_SESSION), ("bandai_issue_order", BANDAI_ISSUE_ORDER)):
        takes = [(label, mocycle.read(files[name])) for label, name in order if name in files]
        out.append(_write(folder, f"{stem}_30fps", takes, None))  # the takes' own rate
        if not quick and fps != 30:
            out.append(_write(folder, f"{stem}_{fps:g}fps", takes, fps))
    # the issue-order session on a game tool's conventions: Mixamo's joint names, metres, Z up, 60 fps
    takes = [(label, mocycle.read(files[name])) for label, name in BANDAI_ISSUE_ORDER if name in files]
    if takes and not quick:
        out.append(_write(folder, "bandai_mixamo_zup_60fps", takes, 60.0, _game_rig))
    pool = [(_label(n), p) for n, p in files.items() if mocycle.read(p).n_frames > 3 * CROSSFADE]
    cache: dict[Path, object] = {}
    rng = random.Random(35)
    for m in minutes:
        need = m * 60 * 30  # frames at the files' 30 fps
        chosen, total = [], 0
        while total < need:
            label, path = rng.choice(pool)
            motion = cache.setdefault(path, mocycle.read(path))
            chosen.append((label, motion))
            total += motion.n_frames - CROSSFADE
        out.append(_write(folder, f"bandai_{m:g}min_{fps:g}fps", chosen, fps))
    return out


#: CMU takes on the iClone rig in session order, with their truth: the walks and the jog are gaits; a dance
#: phrase (05_09, 05_13: arabesques, jetes, a pirouette; the hands' autocorrelation finds no repeat or a weak one)
#: is neither a repeat to loop nor a one-off, so it is not judged; 02_05 is a run of punches at a steady 1.5 s
#: (the hands' autocorrelation 0.65 at 89 frames, 0.74 at 262), not a one-off, and is not judged either;
#: 02_04 (one jump, then balancing) is a one-off gesture.
ICLONE_SESSION = [("walk", "07_12"), ("walk", "07_04"), ("dance", "05_13"), ("walk", "05_01"), ("punch", "02_05"),
                  ("walk", "07_05"), ("gesture", "02_04"), ("walk", "07_02"), ("dance", "05_09"),
                  ("walk", "07_06"), ("walk", "07_03"),
                  ("walk", "07_01"), ("walk", "02_01"), ("run", "02_03"), ("walk", "02_02")]


def _rig(motion) -> tuple:
    return tuple(motion.skeleton.names), tuple(int(p) for p in motion.skeleton.parents)


def iclone_sessions(folder: Path, data: Path) -> list[Session]:
    """One session per rig of :data:`ICLONE_SESSION` (takes in list order; a rig's name is its root joint)."""
    rigs: dict[tuple, list] = {}
    for label, name in ICLONE_SESSION:
        path = data / "cmu-iclone" / f"{name}.bvh"
        if path.is_file():
            motion = mocycle.read(path)
            rigs.setdefault(_rig(motion), []).append((label, motion))
    return [_write(folder, f"iclone_{rig[0][0].lower()}_{takes[0][1].fps:.0f}fps", takes, None)
            for rig, takes in rigs.items() if len(takes) >= 2]


def _onto(motion, first):
    """``motion`` on ``first``'s skeleton (the same joints, another performer's bone lengths): its rotations,
    the first's rest translations, its travel scaled by the ratio of the two skeletons' sizes: one performer."""
    if motion.skeleton.same_as(first.skeleton):
        return motion
    a, b = first.skeleton, motion.skeleton
    if a.names != b.names or list(a.parents) != list(b.parents):
        raise SystemExit(f"cannot join takes of different rigs: {b.names[:3]}... and {a.names[:3]}...")
    j = motion.travel_joint
    up = vertical_axis(first)

    def hip_height(skeleton) -> float:  # the travel joint above the lowest joint, in the rest pose
        P = mocycle.Motion.rest(skeleton).world_positions()[0] @ up
        return float(P[j] - P.min())

    scale = hip_height(a) / hip_height(b)
    resized = mocycle.Motion(a, motion.rotations, first.translations_at(0), first.frame_time,
                             tracks={j: motion.joint_translations(j) * scale})
    return resized.resample(first.fps) if abs(motion.fps - first.fps) > 1e-6 else resized


#: Bandai's joint names as Mixamo names them (a game tool's rig: ``mixamorig:`` joints under an ``Armature``)
MIXAMO_NAMES = {"joint_Root": "Armature", "Hips": "mixamorig:Hips", "Spine": "mixamorig:Spine",
                "Chest": "mixamorig:Spine1", "Neck": "mixamorig:Neck", "Head": "mixamorig:Head",
                **{f"{bandai}_{side[0]}": f"mixamorig:{side}{mixamo}" for side in ("Left", "Right")
                   for bandai, mixamo in (("Shoulder", "Shoulder"), ("UpperArm", "Arm"), ("LowerArm", "ForeArm"),
                                          ("Hand", "Hand"), ("UpperLeg", "UpLeg"), ("LowerLeg", "Leg"),
                                          ("Foot", "Foot"), ("Toes", "ToeBase"))}}


def _game_rig(motion):
    """A Bandai session on a game tool's conventions: Mixamo's joint names, metres (Bandai's centimetres / 100),
    Z up (the root turned +90 degrees about X, as :func:`mocycle.datasets.synthetic.to_z_up` turns a take)."""
    from mocycle.datasets.synthetic import to_z_up
    from mocycle.motion import EndSite, Skeleton

    s, k = motion.skeleton, 0.01
    skeleton = Skeleton(tuple(MIXAMO_NAMES.get(n, n) for n in s.names), s.parents, np.asarray(s.offsets) * k,
                        s.channels, [EndSite(e.parent, tuple(np.asarray(e.offset) * k), e.name) for e in s.end_sites])
    return to_z_up(mocycle.Motion(skeleton, motion.rotations, np.asarray(motion.translations) * k,
                                  motion.frame_time))


def _write(folder: Path, name: str, takes, fps: float | None, rig=None) -> Session:
    """``takes`` joined into a session written to ``folder`` (resampled to ``fps``; ``rig``: a change of
    conventions made on the joined motion), its truth beside it."""
    motions = [t.motion if hasattr(t, "motion") else t for _, t in takes]
    motions = [_onto(m, motions[0]) for m in motions]
    s = join_takes(motions, [label for label, _ in takes], crossfade=CROSSFADE)
    motion, stretches = s.motion, s.stretches
    if rig is not None:
        motion = rig(motion)
    if fps is not None and abs(fps - motion.fps) > 1e-6:
        scale = fps / motion.fps
        motion = motion.resample(fps)
        stretches = [(lab, int(round(a * scale)), min(motion.n_frames, int(round(b * scale))))
                     for lab, a, b in stretches]
        stretches[-1] = (stretches[-1][0], stretches[-1][1], motion.n_frames)
    path = folder / f"{name}.bvh"
    mocycle.write(motion, path)
    # the truth beside the session, for a look at its loops later (``--keep``)
    (folder / f"{name}.truth.json").write_text(json.dumps({"fps": motion.fps, "stretches": stretches}))
    return Session(name, path, stretches, motion.fps, motion.n_frames)


# -- running and measuring ---------------------------------------------------------------------------------------


def run(session: Session, outdir: Path) -> Result:
    out = outdir / session.name
    out.mkdir(parents=True, exist_ok=True)
    cmd = mocycle_cmd() + ["loop", str(session.path), "-o", str(out / "s.bvh"), "--part", "all", "--root",
                           "motion", "--json"]
    with tempfile.TemporaryFile() as so, tempfile.TemporaryFile() as se:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=so, stderr=se)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        so.seek(0)
        se.seek(0)
        text, err = so.read().decode(), se.read().decode(errors="replace")
    try:
        doc = json.loads(text) if text.strip() else None
    except json.JSONDecodeError:
        doc = None
    (out / "s.json").write_text(text)  # the report beside the loops (kept with ``--keep``)
    return Result(session, p.returncode, usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024, doc, err)


def _overlaps(a: int, b: int, stretches) -> list[int]:
    return [max(0, min(b, e) - max(a, s)) for _, s, e in stretches]


def measure(r: Result) -> None:
    s = r.session
    doc = r.doc or {}
    loops = doc.get("loops") or []
    parts = doc.get("parts") or []
    not_looped = {d["part"] for d in doc.get("not_looped") or []}
    body = Body.of(mocycle.read(s.path))
    rows = r.rows
    rows["parts"] = len(parts)
    rows["loopable"] = sum(1 for p in parts if p.get("loop"))
    rows["loops"] = len(loops)
    rows["unaccounted"] = sum(1 for k, p in enumerate(parts) if p.get("loop") and k not in not_looped
                              and not any(lp.get("part") == k for lp in loops))
    owners = []
    spans, bleed_max, off_period, off_turn, one_off = [], 0, [], [], []
    for lp in loops:
        a, b = lp["frames"]
        ov = _overlaps(a, b, s.stretches)
        main = int(np.argmax(ov))
        P = float(lp["period_frames"])
        bleed = sum(ov) - ov[main]
        bleed_max = max(bleed_max, bleed)
        if bleed > 0.5 * P:
            spans.append(f"{lp['kind']} {a}-{b} ({bleed} frames over)")
        label = s.stretches[main][0]
        owners.append((main, lp))
        if label in ONE_OFF:
            one_off.append(f"{lp['kind']} {a}-{b} in a {label}")
        if lp["kind"].startswith(("walk", "run")):
            ruler, _ = body.stride_period(a, b)
        else:
            ruler = body.arms_period(a, b)
        if np.isfinite(ruler) and abs(P / ruler - 1) > PERIOD_TOL:
            off_period.append(f"{lp['kind']} {a}-{b}: {P:.1f} vs {ruler:.1f}")
        take_turn = body.turn_over(a, b, P)
        got = float(lp.get("turn_per_cycle_deg") or 0.0)
        if abs(got - take_turn) > max(10.0, 0.25 * abs(take_turn)):
            off_turn.append(f"{lp['kind']} {a}-{b}: {got:.0f} vs {take_turn:.0f} deg")
    wanted, got = [], []
    for k, (label, a, b) in enumerate(s.stretches):
        if label in GAIT:
            stride, _ = body.stride_period(a, b)
            if not (np.isfinite(stride) and (b - a) / stride >= 1.5):
                continue
        elif label not in REPEATS:
            continue
        wanted.append(k)
        if any(main == k for main, _ in owners):
            got.append(k)
    rows["stretches"] = len(s.stretches)
    rows["wanted"], rows["got"] = len(wanted), len(got)
    rows["missed"] = [f"{s.stretches[k][0]} {s.stretches[k][1]}-{s.stretches[k][2]}" for k in wanted if k not in got]
    rows["turn stretches with a turning loop"] = (
        sum(1 for k, (lab, _, _) in enumerate(s.stretches) if lab == "turn"
            and any(main == k and "turning" in lp["kind"] for main, lp in owners)),
        sum(1 for lab, _, _ in s.stretches if lab == "turn"))
    rows["spans"], rows["bleed_max"] = spans, bleed_max
    rows["off_period"], rows["off_turn"], rows["one_off"] = off_period, off_turn, one_off
    rows["traceback"] = "Traceback" in r.stderr


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the 30 fps and iClone sessions, no timed sizes")
    ap.add_argument("--synthetic-only", action="store_true")
    ap.add_argument("--minutes", default="1,4", help="sizes of the drawn sessions, comma-separated (e.g. 1,4,15,60)")
    ap.add_argument("--fps", type=float, default=120.0, help="frame rate of the drawn sessions")
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--keep", type=Path, default=None, help="write the sessions and loops here")
    args = ap.parse_args(argv)
    minutes = [] if args.quick else [float(m) for m in args.minutes.split(",") if m.strip()]
    print(f"mocycle: {mocycle.__file__}; command: {' '.join(mocycle_cmd())}")
    with tempfile.TemporaryDirectory(prefix="mocycle-sessions-") as tmp:
        root = args.keep or Path(tmp)
        (root / "sessions").mkdir(parents=True, exist_ok=True)
        sessions = synthetic_sessions(root / "sessions", args.quick)
        data = args.data or default_data()
        if not args.synthetic_only:
            if data.is_dir():
                sessions += real_sessions(root / "sessions", data, minutes, args.fps, args.quick)
                sessions += iclone_sessions(root / "sessions", data)
            else:
                print(f"({data} not found: the real sessions are skipped)")
        results = []
        for s in sessions:
            r = run(s, root / "loops")
            measure(r)
            results.append(r)
            print(f"  {s.name}: {s.frames} frames at {s.fps:g} fps, exit {r.code}, {r.rows['loops']} loops, "
                  f"{r.cpu_s:.1f} CPU s, {r.peak_mb:.0f} MB", file=sys.stderr, flush=True)
    print()
    head = (f"{'session':28} {'frames':>8} {'fps':>4} {'exit':>4} {'stretch':>7} {'parts':>5} {'loops':>5} "
            f"{'own loop':>9} {'turning':>7} {'span':>4} {'bleed':>5} {'off P':>5} {'off T':>5} {'1-off':>5} "
            f"{'unacct':>6} {'CPU s':>7} {'wall s':>7} {'peak MB':>8}")
    print(head)
    for r in results:
        w = r.rows
        tl = w["turn stretches with a turning loop"]
        print(f"{r.session.name:28} {r.session.frames:8d} {r.session.fps:4.0f} {r.code:4d} {w['stretches']:7d} "
              f"{w['parts']:5d} {w['loops']:5d} {w['got']:4d}/{w['wanted']:<4d} {tl[0]:3d}/{tl[1]:<3d} "
              f"{len(w['spans']):4d} {w['bleed_max']:5d} {len(w['off_period']):5d} {len(w['off_turn']):5d} "
              f"{len(w['one_off']):5d} {w['unaccounted']:6d} {r.cpu_s:7.1f} {r.wall_s:7.1f} {r.peak_mb:8.0f}")
    print()
    for r in results:
        w = r.rows
        notes = [f"missed: {', '.join(w['missed'])}" if w["missed"] else "",
                 f"spans: {'; '.join(w['spans'])}" if w["spans"] else "",
                 f"off period: {'; '.join(w['off_period'])}" if w["off_period"] else "",
                 f"off turn: {'; '.join(w['off_turn'])}" if w["off_turn"] else "",
                 f"one-off looped: {'; '.join(w['one_off'])}" if w["one_off"] else "",
                 "TRACEBACK" if w["traceback"] else "", f"exit {r.code}" if r.code not in (0, 3) else ""]
        notes = [n for n in notes if n]
        if notes:
            print(f"{r.session.name}: " + " | ".join(notes))
    total = {k: sum(len(r.rows[k]) for r in results) for k in ("spans", "off_period", "off_turn", "one_off")}
    wanted = sum(r.rows["wanted"] for r in results)
    got = sum(r.rows["got"] for r in results)
    bad_exit = [r.session.name for r in results if r.code not in (0, 3) or r.rows["traceback"]]
    unacct = sum(r.rows["unaccounted"] for r in results)
    print(f"\nstretches that should loop: {got} of {wanted} got a loop of their own; loops spanning a border: "
          f"{total['spans']}; off the stride/arms period: {total['off_period']}; off the turn: {total['off_turn']}; "
          f"one-off gestures looped: {total['one_off']}; loopable parts unaccounted for: {unacct}; exit 1 or "
          f"traceback: {len(bad_exit)} {bad_exit if bad_exit else ''}")
    sized = [r for r in results if "min_" in r.session.name]
    if len(sized) >= 2:
        a, b = sized[-2], sized[-1]
        ratio = b.session.frames / a.session.frames
        print(f"growth from {a.session.name} to {b.session.name}: CPU exponent "
              f"{np.log(b.cpu_s / a.cpu_s) / np.log(ratio):.2f}, memory exponent "
              f"{np.log(b.peak_mb / a.peak_mb) / np.log(ratio):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
