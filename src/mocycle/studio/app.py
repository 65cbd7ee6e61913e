"""The studio's web server: a Starlette app whose JSON API calls the task layer.

Routes (``{id}``: a take, ``{job}``: a background job, ``{stroke}``: an authored animation)::

    GET  /                               the page
    GET  /api/takes                      the library: facts and loop figures per take, analysis progress
    GET  /api/options                    the loop and plane options (``tasks.schema``), for the forms
    GET  /api/takes/{id}/motion          the take as a binary payload (world positions per frame)
    POST /api/takes/{id}/loop            re-run ``tasks.loop`` with options (a job)
    GET  /api/takes/{id}/plane           ``tasks.project``: the authoring plane (binary payload)
    POST /api/takes/{id}/relayout        markers moved: RBFP seed + Algorithm 12 (a job, cancellable)
    POST /api/takes/{id}/strokes         ``tasks.author``: a drawn stroke becomes an animation
    GET  /api/strokes/{stroke}/motion    the authored animation (binary payload)
    GET  /api/strokes/{stroke}.bvh|.glb  ... as BVH or glTF binary on the take's skeleton
    GET  /api/jobs/{job}                 a job's status and progress (and its result when done or refused)
    DELETE /api/jobs/{job}               cancel it
    GET  /api/jobs/{job}/motion          a loop job's loop as the viewer plays it (phase-aligned with the take)
    GET  /api/jobs/{job}/loop.bvh|.glb   a loop job's loop as ``mocycle loop -o NAME_loop.bvh|.glb`` writes it

A loop that fails its checks is refused as ``mocycle loop`` refuses it (``tasks.loop`` raises
``LoopRefused``): the job's status is ``refused`` with the reason, and its motion and files answer 409.  The
request's ``force: true`` passes ``force`` on: the loop is made, its failed checks are listed in the job's
result, and the files are named ``NAME_loop.forced.*`` with an ``X-Mocycle-Failed-Checks`` header.
"""

from __future__ import annotations

import contextlib
import itertools
import re
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from .. import tasks
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion, OptionError
from ..tasks import author
from .jobs import Jobs
from .library import Take, find_takes, loop_summary
from .payload import motion_payload, plane_payload
from .review import loop_view

STATIC = Path(__file__).parent / "static"
BINARY = "application/octet-stream"
DOWNLOADS = {".bvh": "text/plain", ".glb": "model/gltf-binary"}
MAX_STROKES = 64  # authored animations kept in memory per server (oldest dropped)


class Studio:
    """The server's state: the library, its background analysis and the interactive jobs."""

    def __init__(self, paths, amc_fps: float = tasks.AMC_FPS, analyse: bool = True):
        self.amc_fps = amc_fps
        self.takes = {f"t{i}": Take(id=f"t{i}", path=p) for i, p in enumerate(find_takes(paths))}
        self.analysis = Jobs(workers=1)
        self.interactive = Jobs(workers=1)
        self.strokes: dict[str, dict] = {}
        self._stroke_ids = itertools.count(1)
        self._planes: dict[tuple, tuple[bytes, dict]] = {}
        self._motions: dict[str, bytes] = {}
        self._relayout: dict[str, str] = {}  # take id -> its running relayout job
        self._lock = threading.Lock()
        if analyse:
            for take in self.takes.values():
                self.analysis.submit("analyse", lambda job, t=take: self._analyse(t))

    # ------------------------------------------------------------ background analysis of the library
    def _analyse(self, take: Take) -> None:
        take.status = "running"
        try:
            motion = take.motion(self.amc_fps)
            take.facts = {"frames": motion.n_frames, "fps": motion.fps, "duration_s": motion.duration,
                          "joints": motion.n_joints}
            try:
                # force: every periodic motion's figures, also of a loop that is refused; loop_summary marks it
                # refused from the same failed checks that make tasks.loop refuse it without force
                report = tasks.loop.run(motion, tasks.loop.Options(which="all", force=True))
                take.loops = [loop_summary(loop) for loop in report.facts["loops"]]
            except NoPeriodicMotion as exc:
                take.reason = str(exc)
            take.status = "done"
        except MocycleError as exc:
            take.status, take.error = "failed", str(exc)

    def take(self, take_id: str) -> Take:
        if take_id not in self.takes:
            raise KeyError(take_id)
        return self.takes[take_id]

    def motion_bytes(self, take: Take) -> bytes:
        """The take's payload, made once."""
        with self._lock:
            data = self._motions.get(take.id)
        if data is None:
            data = motion_payload(take.motion(self.amc_fps), {"name": take.name})
            with self._lock:
                self._motions[take.id] = data
        return data

    # ------------------------------------------------------------ the review: loops with options
    def loop_job(self, take: Take, options: dict):
        """``tasks.loop`` with the form's options; ``force`` as ``mocycle loop --force`` (without it a loop that
        fails its checks ends the job as ``refused``, see :class:`~.jobs.Jobs`)."""
        opts = {k: options[k] for k in ("method", "model", "root", "feet", "cycles") if options.get(k) not in
                (None, "")}
        force = options.get("force", False)
        if not isinstance(force, bool):
            raise ValueError(f"force must be true or false; got {force!r}")
        o = tasks.loop.Options(force=force, **opts)  # an OptionError here is the caller's 400

        def named(text: str) -> str:  # messages name the take as the library lists it, not as "take 0"
            memory = "take 0: "  # how tasks name a motion given in memory
            return f"{take.name}: {text[len(memory):]}" if text.startswith(memory) else text

        def work(job):
            try:
                report = tasks.loop.run(take.motion(self.amc_fps), o)
            except LoopRefused as exc:
                raise LoopRefused(named(str(exc)), exc.failed) from None
            cycle = report.result
            f = report.facts
            phase = np.asarray(cycle.periodic.coords, dtype=np.float64)
            view, view_facts = loop_view(report)
            return {"report": report, "view": view, "take": take, "facts": {
                "loop": loop_summary(f), "options": o.to_dict(), "warnings": [named(w) for w in report.warnings],
                "failed_checks": f["failed_checks"], "forced": bool(f["failed_checks"]),
                "frames_out": f["frames_out"], "phase": phase.round(4).tolist(), "excitation": f["excitation"],
                "view": view_facts, "seconds": report.seconds}}

        return self.interactive.submit("loop", work)

    # ------------------------------------------------------------ the authoring plane
    def plane(self, take: Take, params: dict) -> bytes:
        fields = {"projection", "select", "ratio", "seed_projection", "optimize"}
        o = tasks.project.Options(**{k: v for k, v in params.items() if k in fields}, amc_fps=self.amc_fps)
        key = (take.id, tuple(sorted((k, str(getattr(o, k))) for k in fields)))
        with self._lock:
            if key in self._planes:
                return self._planes[key][0]
        motion = take.motion(self.amc_fps)
        report = tasks.project.run(motion, o)
        data = plane_payload(motion, report.result, {**report.facts, "seconds": report.seconds})
        with self._lock:
            self._planes[key] = (data, report.facts)
        return data

    def relayout_job(self, take: Take, keyframes, markers, optimize: bool):
        with self._lock:
            previous = self._relayout.get(take.id)
        if previous:
            self.interactive.cancel(previous)  # a newer drag supersedes it

        def work(job):
            def progress(fraction):
                job.progress = fraction

            report = author.relayout(take.motion(self.amc_fps), keyframes, markers, optimize,
                                     stop=job.cancelled, progress=progress)
            return {"facts": {**report.facts, "seconds": report.seconds}}

        job = self.interactive.submit("relayout", work)
        with self._lock:
            self._relayout[take.id] = job.id
        return job

    def stroke(self, take: Take, body: dict) -> dict:
        t0 = time.perf_counter()
        opts = {k: body[k] for k in ("plant", "feet") if body.get(k)}
        report = author.run((take.motion(self.amc_fps), body), author.Options(**opts, amc_fps=self.amc_fps))
        sid = f"s{next(self._stroke_ids)}"
        with self._lock:
            self.strokes[sid] = {"take": take.id, "motion": report.motions["authored"], "report": report,
                                 "facts": report.facts}
            while len(self.strokes) > MAX_STROKES:
                self.strokes.pop(next(iter(self.strokes)))
        facts = {k: v for k, v in report.facts.items() if k != "trajectory"}
        return {"id": sid, **facts, "warnings": list(report.warnings), "timings_s": dict(report.timings_s),
                "server_ms": 1000 * (time.perf_counter() - t0)}


# ---------------------------------------------------------------- HTTP
def _error(status: int, message: str) -> JSONResponse:
    return JSONResponse({"error": message}, status_code=status)


def _guard(handler):
    """Errors as JSON: unknown take/job 404, bad options or input 400."""

    async def wrapped(request: Request):
        try:
            return await handler(request)
        except KeyError as exc:
            return _error(404, f"not found: {exc.args[0] if exc.args else ''}")
        except LoopRefused as exc:
            return _error(409, str(exc))
        except OptionError as exc:
            return _error(400, f"{exc.parameter} {exc.reason}")
        except (MocycleError, ValueError, TypeError) as exc:
            return _error(400, str(exc))

    return wrapped


def _file_name(text: str) -> str:
    """``text`` as a plain file name (letters, digits, ``._-``)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._") or "take"


def motion_file(report, role: str, name: str, suffix: str) -> bytes:
    """``report.motions[role]`` as ``mocycle loop -o NAME.bvh|.glb`` writes it (``tasks.clips.for_output``:
    a .glb loop holds the clip ``NAME`` ending in ``_loop``, with its closing frame), as bytes."""
    from ..io import write
    from ..tasks.clips import for_output

    with tempfile.TemporaryDirectory(prefix="mocycle-studio-") as folder:
        path = Path(folder) / f"{name}{suffix}"
        motion, clip = for_output(report, role, path)
        write(motion, path, clip=clip)
        return path.read_bytes()


def _download(data, name: str, headers: dict | None = None) -> Response:
    media = DOWNLOADS.get(Path(name).suffix, BINARY)
    return Response(data, media_type=media, headers={"Content-Disposition": f'attachment; filename="{name}"',
                                                     **(headers or {})})


async def _body(request: Request) -> dict:
    body = await request.json()
    if not isinstance(body, dict):
        raise ValueError("the request body must be a JSON object")
    return body


def create_app(paths=(), *, studio: Studio | None = None, amc_fps: float = tasks.AMC_FPS) -> Starlette:
    """The studio's ASGI app over the takes in ``paths`` (files or folders)."""
    from starlette.concurrency import run_in_threadpool

    st = studio or Studio(paths, amc_fps=amc_fps)

    async def index(request):
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})

    async def list_takes(request):
        takes = [t.to_dict() for t in st.takes.values()]
        done = sum(t["status"] in ("done", "failed") for t in takes)
        return JSONResponse({"takes": takes, "done": done, "total": len(takes)})

    async def options(request):
        return JSONResponse({"loop": tasks.schema(tasks.loop.Options), "plane": tasks.schema(tasks.project.Options),
                             "author": tasks.schema(author.Options)})

    async def take_motion(request):
        take = st.take(request.path_params["id"])
        data = await run_in_threadpool(st.motion_bytes, take)
        return Response(data, media_type=BINARY)

    async def loop(request):
        take = st.take(request.path_params["id"])
        job = st.loop_job(take, await _body(request))
        return JSONResponse(job.to_dict(), status_code=202)

    async def plane(request):
        take = st.take(request.path_params["id"])
        params = dict(request.query_params)
        if "optimize" in params:
            params["optimize"] = params["optimize"] in ("1", "true", "yes")
        data = await run_in_threadpool(st.plane, take, params)
        return Response(data, media_type=BINARY)

    async def relayout(request):
        take = st.take(request.path_params["id"])
        body = await _body(request)
        job = st.relayout_job(take, np.asarray(body["keyframes"], dtype=np.int64),
                              np.asarray(body["markers"], dtype=np.float64), bool(body.get("optimize", True)))
        return JSONResponse(job.to_dict(), status_code=202)

    async def stroke(request):
        take = st.take(request.path_params["id"])
        body = await _body(request)
        return JSONResponse(await run_in_threadpool(st.stroke, take, body))

    async def stroke_motion(request):
        s = st.strokes[request.path_params["stroke"]]
        data = await run_in_threadpool(motion_payload, s["motion"], {"name": "authored"})
        return Response(data, media_type=BINARY)

    def _suffix(request) -> str:
        suffix = "." + request.path_params["suffix"]
        if suffix not in DOWNLOADS:
            raise KeyError(request.url.path)
        return suffix

    async def stroke_file(request):
        sid, suffix = request.path_params["stroke"], _suffix(request)
        s = st.strokes[sid]
        name = f"{_file_name(Path(st.take(s['take']).name).stem)}_authored_{sid}"
        data = await run_in_threadpool(motion_file, s["report"], "authored", name, suffix)
        return _download(data, name + suffix)

    def _job(request):
        job = st.interactive.get(request.path_params["job"]) or st.analysis.get(request.path_params["job"])
        if job is None:
            raise KeyError(request.path_params["job"])
        return job

    async def job_status(request):
        job = _job(request)
        out = job.to_dict()
        if job.status in ("done", "refused") and isinstance(job.result, dict):
            out["result"] = job.result.get("facts")
        return JSONResponse(out)

    async def job_cancel(request):
        job = _job(request)
        job.cancel_event.set()
        return JSONResponse(job.to_dict())

    def _loop_job(request):
        job = _job(request)
        if job.kind == "loop" and job.status == "refused":
            raise LoopRefused(f"{job.error} (ask again with force)")
        if job.status != "done" or job.kind != "loop":
            raise ValueError(f"job {job.id} has no loop ({job.status})")
        return job.result

    async def job_motion(request):
        result = _loop_job(request)
        data = await run_in_threadpool(motion_payload, result["view"], {
            "name": "loop", "forced": result["facts"]["forced"]})
        return Response(data, media_type=BINARY)

    async def job_file(request):
        result = _loop_job(request)
        suffix = _suffix(request)
        name = f"{_file_name(Path(result['take'].name).stem)}_loop"
        data = await run_in_threadpool(motion_file, result["report"], "loop", name, suffix)
        failed = [c["check"] for c in result["facts"]["failed_checks"]]
        if failed:  # forced: the file's name and a header say so
            return _download(data, f"{name}.forced{suffix}", {"X-Mocycle-Failed-Checks": ", ".join(failed)})
        return _download(data, name + suffix)

    g = _guard
    routes = [
        Route("/", index),
        Route("/api/takes", g(list_takes)),
        Route("/api/options", g(options)),
        Route("/api/takes/{id}/motion", g(take_motion)),
        Route("/api/takes/{id}/loop", g(loop), methods=["POST"]),
        Route("/api/takes/{id}/plane", g(plane)),
        Route("/api/takes/{id}/relayout", g(relayout), methods=["POST"]),
        Route("/api/takes/{id}/strokes", g(stroke), methods=["POST"]),
        Route("/api/strokes/{stroke}/motion", g(stroke_motion)),
        Route("/api/strokes/{stroke}.{suffix:str}", g(stroke_file)),
        Route("/api/jobs/{job}", g(job_status)),
        Route("/api/jobs/{job}", g(job_cancel), methods=["DELETE"]),
        Route("/api/jobs/{job}/motion", g(job_motion)),
        Route("/api/jobs/{job}/loop.{suffix:str}", g(job_file)),
        Mount("/static", StaticFiles(directory=STATIC), name="static"),
    ]
    @contextlib.asynccontextmanager
    async def lifespan(app):
        yield
        st.analysis.shutdown()
        st.interactive.shutdown()

    app = Starlette(routes=routes, lifespan=lifespan)
    app.state.studio = st
    return app
