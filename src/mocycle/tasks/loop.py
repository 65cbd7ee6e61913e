"""``loop``: one seamless typical cycle of a take (paper 001 harmonic regression, centroid or cut)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING

from ..defaults import TIME_AXES
from ..errors import Hint, LoopRefused, MocycleError, NoPeriodicMotion, OptionError
from . import fields
from .options import Choice, Constraint, Flag, Integer, Text, option
from .report import Recorder, Report, label_of, load

if TYPE_CHECKING:  # the part pieces come with numpy; the task loads them when it runs
    from ..cycle.parts import PartPiece

#: the loop metrics (``facts["metrics"]``): key -> (label, unit)
METRIC_LABELS = {
    "template_error": ("template error", "rad"),
    "rmse_h": ("RMSE h", "rad"),
    "rmse_dh": ("RMSE h'", "rad/s"),
    "rmse_ddh": ("RMSE h''", "rad/s²"),
    "jerk_ratio": ("jerk, cycle / input", ""),
    "seam_pose": ("seam jump, pose", "× median step"),
    "seam_velocity": ("seam jump, velocity", "× median change"),
    "seam_pose_local": ("seam jump, pose (local)", "× nearby steps"),
    "seam_velocity_local": ("seam jump, velocity (local)", "× nearby changes"),
    "foot_sliding": ("foot sliding, cycle", "units/s"),
    "input_foot_sliding": ("foot sliding, input", "units/s"),
    "skate": ("foot skate, cycle (as fitted)", "units/s"),
    "input_skate": ("foot skate, input", "units/s"),
}


def parse_range(text: str | None, n_frames: int) -> tuple[int, int]:
    """``"START:STOP"`` (frame numbers; negative counts from the end; either may be empty) -> (start, stop)."""
    if not text:
        return 0, n_frames
    try:
        a, _, b = text.partition(":")
        start = int(a) if a.strip() else 0
        stop = int(b) if b.strip() else n_frames
    except ValueError:
        raise OptionError("frame_range", f"must look like START:STOP (frame numbers); got {text!r}") from None
    if start < 0:
        start += n_frames
    if stop < 0:
        stop += n_frames
    if not 0 <= start < stop <= n_frames:
        raise OptionError("frame_range", f"{text} is outside the take's {n_frames} frames")
    return start, stop


@dataclass(frozen=True)
class FrameRange(Constraint):
    """A range of frames as text, ``START:STOP`` (either may be left out or negative), or None: the syntax is
    checked here, the bounds against the take when it is read."""

    def __call__(self, name: str, value) -> str | None:
        if value is None or value == "":
            return None
        if not isinstance(value, str) or ":" not in value:
            raise OptionError(name, f"must look like START:STOP (frame numbers); got {value!r}")
        parse_range(value, 2**62)
        return value

    def schema(self) -> dict:
        return {"anyOf": [{"type": "string", "pattern": r"^-?\d*:-?\d*$"}, {"type": "null"}]}


@dataclass(frozen=True)
class Options(fields.CycleOptions):
    """Options of ``loop``: how the take's cycle is found (:class:`~mocycle.tasks.fields.CycleOptions`, with the
    loop's own words for a few), which part is looped, and how the loop is written."""

    method: str = fields.method("harmonic (regression), centroid (paper 001) or cut (baseline).")
    model: str = fields.model("Harmonic model: M1 (FGLS-weighted positions, velocities, accelerations), M2 "
                              "(positions only; velocity/acceleration off), M3 (unweighted).")
    which: int | str | None = option(  # type: ignore[assignment]  # loop's part may also be 'all'
        None, "Which part of the take to loop: its number in the parts listed (0-based; default: the steady part "
              "with the most cycles), or 'all': one file per part that loops, named OUT.part<k>-<kind>.bvh (kind: "
              "walk-straight, walk-turning-left, run-..., arms, periodic).",
        Integer(0, words={"all": "all"}, optional=True), flag="--part", old_flags=("--class", "--parts"))
    force: bool = option(False, "Write the cycle even when it fails a loop check (longer than the take, fits much "
                                "worse than a plain cut, seam jumps); a warning names the check. It also lets an "
                                "output replace an input file.", Flag())
    root: str = fields.root("inplace", "inplace (walks on the spot, facing kept) or motion (moves on).")
    frame_range: str | None = option(None, "Use frames START:STOP of the take.", FrameRange(), flag="--range")
    step: int | None = option(None, "Find the phase of frames without gait on every STEP-th frame (default: about 30 "
                                    "frames a second, every 4th at 120 fps, and every frame where the feet land).",
                              Integer(1, optional=True))
    cycles: int = fields.cycles(1, "Repeat the cycle this many times in the output.")
    time_axis: str = option("smooth", "Phase to time: smooth (default), rank (thesis eq. 3.20), gmm (eq. 3.21) "
                                      "or line.", Choice(TIME_AXES), flag="--time")
    workers: int | None = option(None, "Processes that loop the parts side by side with --part all (default: the "
                                       "cores this process may use; 1: one after another). The output is the same.",
                                 Integer(1, optional=True))
    scheduler: str | None = option(None, "Loop the parts on a dask cluster: its scheduler's address "
                                         "(tcp://HOST:PORT) instead of local processes.", Text())



def run(take, options: Options | None = None, *, deliver=None) -> Report:
    """Cut the take into steady parts (:func:`~mocycle.activities.segment_activities`) and loop them, each on
    its own frames (:func:`~mocycle.cycle.parts.loop_piece`): a take that does one thing is one part, and no loop
    ever spans a part border.  With ``which="all"`` the parts are looped side by side on ``workers`` processes
    (or a dask cluster at ``scheduler``), each given only its own frames; the result is the same as one after
    another.

    ``motions["loop"]`` is the chosen part's cycle repeated ``cycles`` times with the chosen root; with
    ``which="all"`` every part that loops gets ``motions["loop.part<k>"]`` (``k``: the part's index in
    ``facts["parts"]``).  ``deliver``: a function that writes one loop, given a report of that loop alone
    (what a front end's writer takes), called as each loop is made (in the process that made it); its loops are
    then not kept in the report (their arrays are released once written) and ``extras[role]["written"]`` holds
    what it returned (``{role: (path, written motion's frames, closing frame)}``).  ``facts``: ``status``,
    ``reason`` (plain words), ``loops`` (each loop's figures: ``part``, ``kind``, ``frames``, period, speed, turn
    per cycle, metrics, checks, feet), ``not_looped`` (every part that was not, each with its reason: too short,
    refused by a check, a fit that could not be made), ``parts`` (every part of the take) and, at the top
    level, the figures of the first loop.
    Raises :class:`~mocycle.errors.NoPeriodicMotion` when no part of the take loops and
    :class:`~mocycle.errors.LoopRefused` when every part tried fails a loop check (``force``: a warning
    instead); both carry ``facts`` with the same shape (``status`` ``no-periodic-motion`` or ``refused``).
    """
    import warnings

    from ..activities import nothing_to_loop, segment_activities
    from ..cycle.parts import part_piece, parts_to_try
    from ..errors import MocycleWarning

    o = options or Options()
    everything = o.which == "all"
    with Recorder() as rec, contextlib.ExitStack() as stack:
        motion = load(take, o.amc_fps, o.take)
        start, stop = parse_range(o.frame_range, motion.n_frames)
        motion = motion[start:stop]
        label = label_of(take)
        if o.foot_joints is not None:  # a wrong joint name is the user's mistake, not a part's: said once, first
            from ..contacts import find_feet

            find_feet(motion.skeleton, o.foot_joints)
        pool = _pool(o, motion.n_frames)
        if pool is not None:
            stack.enter_context(pool)  # shut down when the loops are done, or the take refused
        client = _client(o)
        if client is not None:
            stack.enter_context(client)
        with rec.part("parts"):
            acts = segment_activities(motion, min_periods=o.min_periods, joints=o.joints, classes=o.classes,
                                      pca=o.pca, delay=o.delay, step=o.step, map=_mapper(pool, client))
        parts = acts.parts
        loops, not_looped, motions, cycles, extras, refusals = [], [], {}, [], {}, []
        tried = parts_to_try(acts, o.which)
        jobs = (_Job(part_piece(motion, acts, k), o, label, f"loop.part{k}" if everything else "loop", start,
                     deliver) for k in tried)
        for out in _outcomes(jobs, tried, pool, client):
            for text in out.warnings:  # in part order, whichever process made them
                warnings.warn(text, MocycleWarning, stacklevel=2)
            for name, seconds in out.timings.items():
                rec.timings_s[name] = rec.timings_s.get(name, 0.0) + seconds
            k = out.index
            if out.refused is not None:
                exc = LoopRefused(out.refused, out.failed)
                refusals.append(exc)
                not_looped.append(_not_looped(k, parts[k], start, f"refused: {exc}", exc))
                continue
            if out.error is not None:  # NoPeriodicMotion too: this part alone does not loop
                not_looped.append(_not_looped(k, parts[k], start, out.error))
                continue
            loops.append(out.facts)
            role = out.facts["role"]
            if out.written is not None:
                extras[role] = {"written": out.written}
            else:
                motions[role] = out.result
                extras[role] = out.extra
                cycles.append(out.cycle)
            if not everything:
                break
        done = {d["part"] for d in not_looped} | {f["part"] for f in loops}
        for k, p in enumerate(parts):
            if k not in done and (not p.loop or everything):
                not_looped.append(_not_looped(k, p, start, p.reason))
        not_looped.sort(key=lambda d: d["frames"][0])
        if not loops:
            if refusals:
                exc = refusals[0] if len(refusals) == 1 else \
                    LoopRefused("; ".join(map(str, refusals)), [f for r in refusals for f in r.failed])
                exc.facts = _facts("refused", str(exc), [], not_looped, acts, start)
                raise exc
            failures = [d for d in not_looped if d["part"] in tried]
            if failures:  # parts that should have looped, and why each did not
                reason = "; ".join(f"part {d['part']} ({d['kind']}, frames {d['frames'][0]}-{d['frames'][1]}) does "
                                   f"not loop: {d['reason']}" for d in failures)
            else:
                reason = nothing_to_loop(acts)
            none_found = NoPeriodicMotion(reason)
            none_found.facts = _facts("no-periodic-motion", reason, [], not_looped, acts, start)
            raise none_found
    motions["input"] = motion
    facts = _facts("ok", _chosen_reason(loops, parts, everything), loops, not_looped, acts, start)
    return rec.report("loop", facts, motions, cycles if everything else (cycles[0] if cycles else None), extras)


#: Below this many frames to loop, the parts are looped one after another (starting processes costs more).
PARALLEL_FRAMES = 20_000


@dataclass(frozen=True)
class _Job:
    """One part to loop, with all it needs: sent as it is to another process or a dask worker."""

    piece: PartPiece
    options: Options
    label: str
    role: str
    first: int      # the range's first frame in the file (frames in the facts are the file's)
    deliver: Callable[[Report], dict] | None = None


@dataclass
class _Outcome:
    """What became of one part: its facts and loop (or, delivered, what was written), or why it did not loop;
    the warnings and stage times it made."""

    index: int
    facts: dict | None = None
    result: object = None
    cycle: object = None
    extra: dict | None = None
    written: dict | None = None
    refused: str | None = None
    failed: list = field(default_factory=list)
    error: str | None = None
    warnings: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)


def _outcome(job: _Job) -> _Outcome:
    """Loop one part (in whichever process runs it): its outcome, never an exception but a usage error."""
    import warnings

    from .report import _Part

    piece = job.piece
    out = _Outcome(index=piece.index)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            facts, result, extra, cycle = _loop_one(piece, job.options, job.label, lambda n: _Part(out.timings, n))
        except LoopRefused as exc:
            out.refused, out.failed = str(exc.args[0] if exc.args else exc), list(exc.failed)
        except OptionError:
            raise
        except MocycleError as exc:
            out.error = str(exc)
        else:
            facts["role"] = job.role
            facts["frames"] = [f + job.first for f in facts["frames"]]
            facts["excitation"] = [[a + job.first, b + job.first] for a, b in facts["excitation"]]
            out.facts = facts
            if job.deliver is None:
                out.result, out.cycle, out.extra = result, cycle, extra
            else:  # written now, in this process; only what was written goes back
                report = Report(task="loop", facts={**facts, "loops": [facts]}, warnings=(), timings_s={},
                                motions={job.role: result}, result=[cycle], extras={job.role: extra})
                out.written = {role: (str(path), written.n_frames, written.n_frames != result.n_frames)
                               for role, (path, written) in job.deliver(report).items()}
    out.warnings = [str(w.message) for w in caught
                    if not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning))]
    return out


def workers_for(options: Options) -> int:
    """The processes ``loop`` may use: ``options.workers``, else the cores this process may use; one inside a
    process that may not start others (a daemon: a batch or dask worker)."""
    import multiprocessing
    import os

    if multiprocessing.current_process().daemon:
        return 1
    if options.workers is not None:
        return options.workers
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _pool(o: Options, n_frames: int):
    """The local processes that look at a long take's stretches and loop its parts side by side (``None``: one
    after another here, or on a dask cluster): with ``which="all"``, ``workers_for(o)`` of two or more and a take
    of :data:`PARALLEL_FRAMES` or more.  Forked where the platform forks: the workers start warm (the code
    imported) and share this process's pages until they write them; each is sent its own frames."""
    if o.which != "all" or o.scheduler is not None or n_frames < PARALLEL_FRAMES or workers_for(o) < 2:
        return None
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    methods = multiprocessing.get_all_start_methods()
    return ProcessPoolExecutor(max_workers=workers_for(o),
                               mp_context=multiprocessing.get_context("fork" if "fork" in methods else "spawn"))


def _client(o: Options):
    """A dask client of the cluster at ``o.scheduler`` for ``loop --part all`` (``None`` without one): the
    stretches the cut looks at one by one and the parts are sent there, each with its own frames."""
    if o.scheduler is None or o.which != "all":
        return None
    from distributed import Client

    return Client(o.scheduler, timeout="30s")


def _mapper(pool, client):
    """How the cut maps its stretches: on the local ``pool``, on the dask cluster of ``client``, or here."""
    if pool is not None:
        return partial(pool.map, chunksize=1)
    return map if client is None else partial(_cluster_map, client)


def _cluster_map(client, fn, items) -> list:
    """``map(fn, items)`` on the dask cluster of ``client``, the results in the order of ``items``."""
    futures = client.map(fn, list(items), pure=False)
    try:
        return client.gather(futures)
    finally:
        client.cancel(futures)


def _outcomes(jobs, tried: list[int], pool, client):
    """Each part's :class:`_Outcome`, in the order of ``tried``: one after another, on the local ``pool``, or on
    the dask cluster of ``client``, each sent its part's frames only."""
    if client is not None and len(tried) > 1:
        futures = [client.submit(_outcome, job, pure=False) for job in jobs]
        for future in futures:  # in part order, each as soon as it and those before are done
            yield future.result()
            future.release()
        return
    if pool is None or len(tried) < 2:
        yield from map(_outcome, jobs)
        return
    yield from pool.map(_outcome, jobs, chunksize=1)


def _not_looped(k, part, offset: int, reason: str, exc=None) -> dict:
    d = {"part": k, "kind": part.kind, "frames": [offset + part.start, offset + part.stop], "reason": reason}
    if isinstance(exc, LoopRefused):
        d["failed_checks"] = [f.to_dict() for f in exc.failed]
    return d


#: every :func:`output_tag` of a loop with ``--part all``, as a regular expression (batch claims those names
#: before any take has run, when the parts are not known yet)
TAG_PATTERN = r"part\d+-[a-z-]+"


def output_tag(facts) -> str | None:
    """What a loop's output name adds before its suffix (``OUT.<tag>.bvh``), from its figures: ``None`` for the
    one loop (``role`` ``loop``), ``part1-walk-turning-left`` for a part of ``--part all``.  The CLI and batch
    name files (and plots) by it."""
    role = facts.get("role", "loop")
    if role == "loop":
        return None
    return f"{role.split('.', 1)[1]}-{facts['kind'].replace(' ', '-')}"


def output_path(target, facts):
    """``target`` (a ``pathlib.Path``) with :func:`output_tag` of a loop's figures before its suffix."""
    tag = output_tag(facts)
    return target if tag is None else target.with_suffix(f".{tag}{target.suffix}")


def _chosen_reason(loops, parts, everything) -> str:
    if everything:
        return f"{len(loops)} loop(s) of {sum(1 for p in parts if p.loop)} part(s) that loop"
    f = loops[0]
    if len(parts) == 1:
        return parts[0].reason if parts[0].one_cycle else "the take does one thing: it is one part, looped"
    others = sum(1 for p in parts if p.loop) - 1
    return (f"looped part {f['part']} ({f['kind']}, frames {f['frames'][0]}-{f['frames'][1]}): the steady part with "
            f"the most cycles" + (f"; {others} other part(s) can loop too ({Hint('part', 'all')} writes every one)"
                                  if others > 0 else ""))


def _facts(status, reason, loops, not_looped, acts, offset) -> dict:
    parts = []
    for p in acts.parts if acts is not None else []:
        d = p.to_dict()
        d["frames"] = [d["frames"][0] + offset, d["frames"][1] + offset]
        d["landings"] = {k: [f + offset for f in v] for k, v in d["landings"].items()}
        parts.append(d)
    first = dict(loops[0]) if loops else {}
    return {**first, "status": status, "reason": reason, "loops": loops, "not_looped": not_looped,
            "parts": parts, "first_frame": int(offset)}


def _loop_one(piece, o, label, timer):
    """A part's loop (:func:`~mocycle.cycle.parts.loop_piece`), its feet and its facts (frames of the range).
    Returns ``(facts, repeated cycle, extras, cycle)``; raises LoopRefused and MocycleError."""
    from ..cycle.parts import loop_piece
    from .feet_option import clean_feet

    looped = loop_piece(piece, method=o.method, model=o.model, harmonics=o.harmonics, time_axis=o.time_axis,
                        force=o.force, label=label, timer=timer)
    fitted, part, metrics, offset = looped.cycle, looped.part, looped.metrics, looped.offset
    with timer("feet"):
        frames = fitted.axis.frames()   # the swing clearance of the looped region of the take
        # the fitted cycle's skate is the metrics' when the feet are the ones found by name
        cycle, feet_facts, contacts = clean_feet(fitted, o.feet, o.root, o.foot_joints,
                                                 reference=piece.motion[frames[0]:frames[-1] + 1],
                                                 before=fitted.repeat(2, root="motion"),
                                                 skate_before=None if o.foot_joints else metrics["skate"])
    with timer("cycle"):
        result = cycle.repeat(o.cycles, root=o.root)
    regions = [[int(s) + offset, int(e) + offset] for s, e in cycle.axis.regions]
    facts = {
        "part": looped.index,
        "kind": part.kind,
        "frames": [regions[0][0], regions[-1][1]],
        "frames_in": part.n_frames,
        "frames_out": result.n_frames,
        "fps": piece.motion.fps,
        **cycle.to_dict(),
        "speed": _speed(cycle),
        "excitation": regions,
        "model": o.model if o.method == "harmonic" else None,
        "root": o.root,
        "cycles": o.cycles,
        "metrics": metrics,
        "failed_checks": [f.to_dict() for f in looped.failed],
        "feet": feet_facts,
        "excited_regions": len(cycle.periodic.excitation),
    }
    return facts, result, {"fitted": fitted, "contacts": contacts, "offset": offset}, cycle


def _speed(cycle) -> float:
    """Units per second of the loop's travel (horizontal distance per cycle over the cycle's time)."""
    import numpy as np

    move = np.asarray(cycle.to_dict()["travel_per_cycle"], dtype=np.float64)
    up = np.asarray(cycle.space.world_up, dtype=np.float64)
    flat = move - (move @ up) * up
    return float(np.linalg.norm(flat) / (cycle.period_frames * cycle.space.frame_time))
