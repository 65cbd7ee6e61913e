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
    GET  /api/strokes/{stroke}.bvh       ... as BVH on the take's skeleton
    GET  /api/jobs/{job}                 a job's status and progress (and its result when done)
    DELETE /api/jobs/{job}               cancel it
    GET  /api/jobs/{job}/motion, /api/jobs/{job}/loop.bvh   a loop job's motion
"""

from __future__ import annotations

import contextlib
import itertools
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
from ..errors import MocycleError, NoPeriodicMotion, OptionError
from ..io.bvh import format_bvh
from ..tasks import author
from .jobs import Jobs
from .library import Take, find_takes, loop_summary
from .payload import motion_payload, plane_payload

STATIC = Path(__file__).parent / "static"
BINARY = "application/octet-stream"
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
        opts = {k: options[k] for k in ("method", "model", "root", "feet", "cycles") if options.get(k) not in
                (None, "")}
        o = tasks.loop.Options(force=True, **opts)  # an OptionError here is the caller's 400

        def work(job):
            report = tasks.loop.run(take.motion(self.amc_fps), o)
            cycle = report.result
            f = report.facts
            phase = np.asarray(cycle.periodic.coords, dtype=np.float64)
            return {"report": report, "facts": {
                "loop": loop_summary(f), "options": o.to_dict(), "warnings": list(report.warnings),
                "frames_out": f["frames_out"], "phase": phase.round(4).tolist(), "excitation": f["excitation"],
                "seconds": report.seconds}}

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
            self.strokes[sid] = {"take": take.id, "motion": report.motions["authored"], "facts": report.facts}
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
        except OptionError as exc:
            return _error(400, f"{exc.parameter} {exc.reason}")
        except (MocycleError, ValueError, TypeError) as exc:
            return _error(400, str(exc))

    return wrapped


def _download(text: str, name: str) -> Response:
    return Response(text, media_type="text/plain", headers={"Content-Disposition": f'attachment; filename="{name}"'})


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

    async def stroke_bvh(request):
        sid = request.path_params["stroke"]
        s = st.strokes[sid]
        name = Path(st.take(s["take"]).name).stem
        return _download(await run_in_threadpool(format_bvh, s["motion"]), f"{name}.authored.{sid}.bvh")

    def _job(request):
        job = st.interactive.get(request.path_params["job"]) or st.analysis.get(request.path_params["job"])
        if job is None:
            raise KeyError(request.path_params["job"])
        return job

    async def job_status(request):
        job = _job(request)
        out = job.to_dict()
        if job.status == "done" and isinstance(job.result, dict):
            out["result"] = job.result.get("facts")
        return JSONResponse(out)

    async def job_cancel(request):
        job = _job(request)
        job.cancel_event.set()
        return JSONResponse(job.to_dict())

    def _loop_motion(request):
        job = _job(request)
        if job.status != "done" or job.kind != "loop":
            raise ValueError(f"job {job.id} has no loop ({job.status})")
        return job.result["report"].motions["loop"]

    async def job_motion(request):
        motion = _loop_motion(request)
        data = await run_in_threadpool(motion_payload, motion, {"name": "loop"})
        return Response(data, media_type=BINARY)

    async def job_bvh(request):
        motion = _loop_motion(request)
        return _download(await run_in_threadpool(format_bvh, motion), f"loop.{request.path_params['job']}.bvh")

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
        Route("/api/strokes/{stroke}.bvh", g(stroke_bvh)),
        Route("/api/jobs/{job}", g(job_status)),
        Route("/api/jobs/{job}", g(job_cancel), methods=["DELETE"]),
        Route("/api/jobs/{job}/motion", g(job_motion)),
        Route("/api/jobs/{job}/loop.bvh", g(job_bvh)),
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
