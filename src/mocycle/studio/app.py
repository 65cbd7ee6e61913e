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

import asyncio
import contextlib
import itertools
import os
import re
import shutil
import tempfile
import threading
import time
import traceback
import weakref
from dataclasses import dataclass
from http import HTTPStatus
from pathlib import Path

import numpy as np
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.middleware import Middleware
from starlette.requests import ClientDisconnect, Request
from starlette.responses import HTMLResponse, JSONResponse, Response, StreamingResponse
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from .. import tasks
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion, OptionError
from ..tasks import author, words
from ..tasks.report import Labelled
from ..tasks.spec import SPECS
from . import validate as v
from .guard import MAX_BODY, Access, Guard
from .jobs import Held, Jobs, held_bytes, release_memory
from .library import Take, display, find_takes, loop_summary
from .payload import motion_payload, plane_payload
from .review import loop_view, strip_excitation, strip_parts, take_phase

STATIC = Path(__file__).parent / "static"
BINARY = "application/octet-stream"
DOWNLOADS = {".bvh": "text/plain", ".glb": "model/gltf-binary"}
MB = 1 << 20


@dataclass(frozen=True)
class Limits:
    """What one studio server holds at most (``mocycle studio`` uses the defaults; docs/studio.md lists them)."""

    max_body: int = MAX_BODY  #: bytes of one request body (413 above)
    max_stroke_frames: int = 12_000  #: frames of one authored animation (400 above)
    max_strokes: int = 32  #: authored animations kept (least recently used evicted; 410 after)
    max_stroke_bytes: int = 256 * MB  #: ... and their bytes together
    max_jobs_kept: int = 16  #: finished loop and re-layout jobs kept (least recently used evicted; 410 after)
    max_job_bytes: int = 256 * MB  #: ... and their results' bytes together
    max_pending: int = 8  #: loop and re-layout jobs waiting or running at once (429 above)
    max_planes: int = 16  #: authoring planes kept (made again when asked after eviction)
    max_payloads: int = 4  #: takes' motion payloads kept (made again when asked after eviction)


class Studio:
    """The server's state: the library, its background analysis and the interactive jobs."""

    def __init__(self, paths, amc_fps: float = tasks.AMC_FPS, analyse: bool = True, limits: Limits | None = None):
        self.amc_fps = amc_fps
        self.limits = lim = limits or Limits()
        self.takes = {f"t{i}": take for i, take in enumerate(find_takes(paths))}
        for tid, take in self.takes.items():
            take.id = tid
        ids = itertools.count(1)  # one job numbering for both queues
        self.analysis = Jobs(workers=1, ids=ids)
        self.interactive = Jobs(workers=1, ids=ids, max_pending=lim.max_pending, keep=lim.max_jobs_kept,
                                keep_bytes=lim.max_job_bytes, size=lambda job: held_bytes(job.result, self._shared()))
        self.strokes = Held("stroke", lim.max_strokes, lim.max_stroke_bytes)
        self._stroke_ids = itertools.count(1)
        self._planes = Held("plane", lim.max_planes, 1 << 62)
        self._motions = Held("payload", lim.max_payloads, 1 << 62)
        self._relayout: dict[str, str] = {}  # take id -> its running relayout job
        self._lock = threading.Lock()
        #: the downloads' files (:class:`Downloads`), removed with the server
        self.files = Path(tempfile.mkdtemp(prefix="mocycle-studio-"))
        weakref.finalize(self, shutil.rmtree, self.files, True)
        if analyse:
            for take in self.takes.values():
                self.analysis.submit("analyse", lambda job, t=take: self._analyse(t))

    def _shared(self) -> set[int]:
        """The ids of what the library holds anyway (takes and their motions): not counted in a result's bytes."""
        out = set()
        for take in self.takes.values():
            out.add(id(take))
            if take._motion is not None:
                out.add(id(take._motion))
        return out

    def held(self) -> dict:
        """How much the server holds now (jobs, strokes, caches): for tests and the fuzz benchmark."""
        return {"jobs": self.interactive.held(), "job_bytes": self.interactive.finished.bytes,
                "strokes": len(self.strokes), "stroke_bytes": self.strokes.bytes, "planes": len(self._planes),
                "payloads": len(self._motions)}

    # ------------------------------------------------------------ background analysis of the library
    def _analyse(self, take: Take) -> None:
        """Read and loop one take of the library; whatever happens, it ends ``done`` or ``failed`` (never left
        ``running``): a bad file or a bug is its message, not the end of the analysis."""
        if take.status == "refused":  # a link out of the served folder: never read
            return
        take.status = "running"
        try:
            motion = take.motion(self.amc_fps)
            take.facts = {"frames": motion.n_frames, "fps": motion.fps, "duration_s": motion.duration,
                          "joints": motion.n_joints}
            try:
                # force: every periodic motion's figures, also of a loop that is refused; loop_summary marks it
                # refused from the same failed checks that make tasks.loop refuse it without force
                report = tasks.loop.run(motion, tasks.loop.Options(which="all", force=True, workers=1))
                take.loops = [loop_summary(loop) for loop in report.facts["loops"]]
            except NoPeriodicMotion as exc:
                take.reason = display(str(exc))
            take.status = "done"
        except MocycleError as exc:
            take.status, take.error = "failed", display(str(exc))
        except MemoryError:
            take.status, take.error = "failed", "out of memory: this take needs more than the studio may use"
        except Exception as exc:  # a bug: said on the page and the terminal, the analysis goes on
            traceback.print_exc()
            take.status, take.error = "failed", display(f"internal error: {type(exc).__name__}: {exc}"[:300])
        finally:
            if take.status == "running":  # interrupted (the server stopping)
                take.status, take.error = "failed", "the analysis was interrupted"

    def take(self, take_id: str) -> Take:
        take = self.takes.get(v.path_id("take", take_id))
        if take is None:
            raise v.HTTPProblem(f"no take {take_id}", HTTPStatus.NOT_FOUND)
        return take

    def job(self, job_id: str):
        v.path_id("job", job_id)
        job = self.interactive.get(job_id) or self.analysis.get(job_id)
        return job if job is not None else self.interactive.find(job_id)  # GONE or NOT_FOUND

    def stroke_of(self, stroke_id: str) -> dict:
        v.path_id("stroke", stroke_id)
        s = self.strokes.peek(stroke_id)
        if s is not None:
            return s
        if self.strokes.was_evicted(stroke_id):
            raise v.HTTPProblem(f"stroke {stroke_id} is gone: only the last {self.limits.max_strokes} authored "
                                "animations are kept (and as many as fit the studio's memory budget); draw it again",
                                HTTPStatus.GONE)
        raise v.HTTPProblem(f"no stroke {stroke_id}", HTTPStatus.NOT_FOUND)

    def motion_bytes(self, take: Take) -> bytes:
        """The take's payload, made once (while it stays among the last few asked for)."""
        data = self._motions.peek(take.id)
        if data is None:
            data = motion_payload(take.motion(self.amc_fps), {"name": take.name})
            self._motions.put(take.id, data, len(data))
        return data

    # ------------------------------------------------------------ the review: loops with options
    def loop_job(self, take: Take, options: dict, force: bool):
        """``tasks.loop`` with the form's options; ``force`` as ``mocycle loop --force`` (without it a loop that
        fails its checks ends the job as ``refused``, see :class:`~.jobs.Jobs`)."""
        o = tasks.loop.Options(force=force, **options)  # an OptionError here is the caller's 400

        def work(job):  # messages name the take as the library lists it
            report = tasks.loop.run(Labelled(take.motion(self.amc_fps), take.name), o)
            f = report.facts
            view, view_facts = loop_view(report)
            return {"report": report, "view": view, "take": take, "files": Downloads(self.files), "facts": {
                "loop": loop_summary(f), "options": o.to_dict(),
                "warnings": [words.hints(w) for w in report.warnings],
                "failed_checks": f["failed_checks"], "forced": bool(f["failed_checks"]),
                "frames_out": f["frames_out"], "phase": take_phase(report), "excitation": strip_excitation(report),
                "parts": strip_parts(report),
                "view": view_facts, "seconds": report.seconds}}

        return self.interactive.submit("loop", work)

    # ------------------------------------------------------------ the authoring plane
    def plane(self, take: Take, params: dict) -> bytes:
        fields = v.form_fields("project")
        o = tasks.project.Options(**params, amc_fps=self.amc_fps)
        key = repr((take.id, tuple(sorted((k, str(getattr(o, k))) for k in fields))))
        data = self._planes.peek(key)
        if data is not None:
            return data
        motion = take.motion(self.amc_fps)
        report = tasks.project.run(motion, o)
        arrays = report.result
        assert isinstance(arrays, dict)  # tasks.project's points, keyframes and optimised points
        data = plane_payload(motion, arrays, {**report.facts, "seconds": report.seconds})
        self._planes.put(key, data, len(data))
        return data

    def relayout_job(self, take: Take, body: dict):
        motion = take.motion(self.amc_fps)
        keyframes, markers, optimize = v.relayout_request(body, motion.n_frames)
        with self._lock:
            previous = self._relayout.get(take.id)
        if previous:
            self.interactive.cancel(previous)  # a newer drag supersedes it

        def work(job):
            def progress(fraction):
                job.progress = fraction

            report = author.relayout(motion, np.asarray(keyframes, dtype=np.int64),
                                     np.asarray(markers, dtype=np.float64), optimize,
                                     stop=job.cancelled, progress=progress)
            return {"facts": {**report.facts, "seconds": report.seconds}}

        job = self.interactive.submit("relayout", work)
        with self._lock:
            self._relayout[take.id] = job.id
        return job

    def stroke(self, take: Take, body: dict) -> dict:
        t0 = time.perf_counter()
        motion = take.motion(self.amc_fps)
        asked = v.stroke_request(body, motion.n_frames, motion.frame_time, self.limits.max_stroke_frames)
        report = author.run((motion, asked["stroke"]), author.Options(**asked["options"], amc_fps=self.amc_fps))
        sid = f"s{next(self._stroke_ids)}"
        kept = {"take": take.id, "motion": report.motions["authored"], "report": report,
                "files": Downloads(self.files)}
        facts = {k: val for k, val in report.facts.items() if k != "trajectory"}
        warnings, timings = [words.hints(w) for w in report.warnings], dict(report.timings_s)
        self.strokes.put(sid, kept, held_bytes(kept, self._shared()))
        del report, kept
        release_memory()  # what the work made and dropped
        return {"id": sid, **facts, "warnings": warnings, "timings_s": timings,
                "server_ms": 1000 * (time.perf_counter() - t0)}


# ---------------------------------------------------------------- HTTP
def _clean(value):
    """``value`` with every string valid UTF-8 (a non-UTF-8 file name's bytes shown as ``\\xff``)."""
    if isinstance(value, str):
        return display(value)
    if isinstance(value, dict):
        return {_clean(k): _clean(x) for k, x in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(x) for x in value]
    return value


class JSON(JSONResponse):
    """JSON whose strings are valid UTF-8 whatever file names they carry, and whose figures that could not be
    measured (NaN: the foot skate of a rig whose feet are not found by name) are null (strict JSON: the
    page's parser refuses NaN, and a NaN in one take's figures made the whole library a 500)."""

    def render(self, content) -> bytes:
        try:
            return super().render(content)
        except ValueError:  # a string that is not UTF-8 (UnicodeEncodeError) or a number that is not finite
            from ..text import json_text

            return json_text(_clean(content), indent=None).encode("utf-8")


def _error(status: int, message: str) -> JSONResponse:
    return JSON({"error": display(message)}, status_code=status)


def answers(handler):
    """The handler's errors as JSON, one message each: the request's own problem (:class:`~.validate.
    HTTPProblem`: 400, 404, 410, 413, 429), a loop refused 409, bad options or input 400; anything else is
    the studio's fault: 500 with the message (and a traceback on the server's terminal)."""

    async def wrapped(request: Request):
        try:
            return await handler(request)
        except ClientDisconnect:  # the client left before its body arrived: no one to answer, nothing to say
            return Response(status_code=400)
        except v.HTTPProblem as exc:
            return _error(exc.status, str(exc))
        except LoopRefused as exc:
            return _error(409, str(exc))
        except OptionError as exc:
            return _error(400, f"{exc.parameter} {exc.reason}")
        except MocycleError as exc:
            return _error(400, str(exc))
        except Exception as exc:  # a bug: say so in one line, keep serving
            traceback.print_exc()
            return _error(500, f"internal error: {type(exc).__name__}")

    return wrapped


def _file_name(text: str) -> str:
    """``text`` as a plain file name (letters, digits, ``._-``)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._") or "take"


def write_motion_file(report, role: str, path: Path) -> Path:
    """``report.motions[role]`` written to ``path`` as ``mocycle loop -o NAME.bvh|.glb`` writes it
    (``tasks.clips.for_output``: a .glb loop holds the clip ``NAME`` ending in ``_loop``, with its closing
    frame)."""
    from ..io import write
    from ..tasks.clips import for_output

    motion, clip = for_output(report, role, path)
    return write(motion, path, clip=clip)


def _remove_files(paths: dict) -> None:
    for path in paths.values():
        with contextlib.suppress(OSError):
            path.unlink()


class Downloads:
    """The files of one loop job or authored animation, each made once (the first request makes it, the others
    wait for it) and kept on disk while the job or animation is kept: removed when it is dropped (evicted), so
    the disk holds at most the kept jobs' and strokes' files and memory none of them."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.paths: dict[str, Path] = {}
        self.lock = threading.Lock()
        weakref.finalize(self, _remove_files, self.paths)

    def get(self, name: str, make) -> Path:
        """The file ``name`` (made by ``make(path)`` the first time)."""
        with self.lock:
            path = self.paths.get(name)
            if path is None or not path.exists():
                self.folder.mkdir(parents=True, exist_ok=True)
                target = Path(tempfile.mkdtemp(prefix="dl-", dir=self.folder)) / name
                path = self.paths[name] = make(target)
            return path


#: bytes an answer sends at a time: a slow reader holds this much of the server's memory, not the whole file
CHUNK = 256 << 10


def _bytes_answer(data: bytes, media: str = BINARY, headers: dict | None = None) -> Response:
    """``data`` sent a :data:`CHUNK` at a time (uvicorn waits for each to drain): many slow clients of one
    large payload share the one copy instead of each buffering it."""
    if len(data) <= CHUNK:
        return Response(data, media_type=media, headers=headers)
    view = memoryview(data)

    async def pieces():
        for at in range(0, len(view), CHUNK):
            yield bytes(view[at:at + CHUNK])

    return StreamingResponse(pieces(), media_type=media, headers={"Content-Length": str(len(data)),
                                                                  **(headers or {})})


def _file_answer(path: Path, name: str, headers: dict | None = None) -> Response:
    """The file ``path`` as the download ``name``, read and sent a :data:`CHUNK` at a time (opened now: a file
    removed meanwhile is still sent whole)."""
    fh = open(path, "rb")  # noqa: SIM115 - closed by the stream
    size = os.fstat(fh.fileno()).st_size

    async def pieces():
        try:
            while chunk := await run_in_threadpool(fh.read, CHUNK):
                yield chunk
        finally:
            fh.close()

    media = DOWNLOADS.get(Path(name).suffix, BINARY)
    return StreamingResponse(pieces(), media_type=media, headers={
        "Content-Length": str(size), "Content-Disposition": f'attachment; filename="{name}"', **(headers or {})})


#: seconds a request body may take to arrive (408 after)
BODY_TIMEOUT_S = 30.0


async def _body(request: Request) -> dict:
    try:  # the Guard cut it off past the body limit (413)
        raw = await asyncio.wait_for(request.body(), BODY_TIMEOUT_S)
    except TimeoutError:
        raise v.HTTPProblem(f"the request body did not arrive within {BODY_TIMEOUT_S:g} s",
                            HTTPStatus.REQUEST_TIMEOUT) from None
    return v.parse_body(raw)


def _suffix(request) -> str:
    suffix = "." + request.path_params["suffix"]
    if suffix not in DOWNLOADS:
        raise v.HTTPProblem(f"no {suffix[:20]} download (only {', '.join(DOWNLOADS)})", HTTPStatus.NOT_FOUND)
    return suffix


def _studio(request) -> Studio:
    return request.app.state.studio


# ---------------------------------------------------------------- the handlers (one per route)
_PAGE = None


async def index(request):
    """The page, with the server's token (for the page's own requests) and this answer's script nonce."""
    global _PAGE
    if _PAGE is None:
        _PAGE = (STATIC / "index.html").read_text(encoding="utf-8")
    nonce = request.scope["state"].get("csp_nonce", "")
    token = request.app.state.access.token
    html = _PAGE.replace("<script", f'<script nonce="{nonce}"').replace(
        "<head>", f'<head>\n<meta name="mocycle-token" content="{token}">', 1)
    return HTMLResponse(html, headers={"Cache-Control": "no-store"})


async def list_takes(request):
    takes = [t.to_dict() for t in _studio(request).takes.values()]
    done = sum(t["status"] in ("done", "failed", "refused") for t in takes)
    return JSON({"takes": takes, "done": done, "total": len(takes)})


async def options(request):
    """The forms of the page, made from the tasks' specs: each form's schema (``tasks.schema``), and under
    ``forms`` the fields the page shows (a spec's ``studio``), with ``cycles`` bounded by :data:`MAX_CYCLES`."""
    forms = {"loop": "loop", "plane": "project", "author": "author"}
    out = {form: tasks.schema(SPECS[task].options) for form, task in forms.items()}
    out["loop"]["properties"]["cycles"]["maximum"] = v.MAX_CYCLES
    return JSON({**out, "forms": {form: list(SPECS[task].studio) for form, task in forms.items()}})


async def take_motion(request):
    st = _studio(request)
    data = await run_in_threadpool(st.motion_bytes, st.take(request.path_params["id"]))
    return _bytes_answer(data)


async def loop(request):
    st = _studio(request)
    take = st.take(request.path_params["id"])
    opts, force = v.loop_request(await _body(request))
    return JSON(st.loop_job(take, opts, force).to_dict(), status_code=202)


async def plane(request):
    st = _studio(request)
    take = st.take(request.path_params["id"])
    data = await run_in_threadpool(st.plane, take, v.plane_query(request.query_params))
    return _bytes_answer(data)


async def relayout(request):
    st = _studio(request)
    take = st.take(request.path_params["id"])
    body = await _body(request)
    job = await run_in_threadpool(st.relayout_job, take, body)
    return JSON(job.to_dict(), status_code=202)


async def stroke(request):
    st = _studio(request)
    take = st.take(request.path_params["id"])
    body = await _body(request)
    return JSON(await run_in_threadpool(st.stroke, take, body))


async def stroke_motion(request):
    s = _studio(request).stroke_of(request.path_params["stroke"])
    data = await run_in_threadpool(motion_payload, s["motion"], {"name": "authored"})
    return _bytes_answer(data)


async def stroke_file(request):
    st = _studio(request)
    sid, suffix = request.path_params["stroke"], _suffix(request)
    s = st.stroke_of(sid)
    name = f"{_file_name(Path(st.takes[s['take']].name).stem)}_authored_{sid}"
    path = await run_in_threadpool(s["files"].get, name + suffix,
                                   lambda target: write_motion_file(s["report"], "authored", target))
    return _file_answer(path, name + suffix)


async def job_status(request):
    job = _studio(request).job(request.path_params["job"])
    out = job.to_dict()
    if job.status in ("done", "refused") and isinstance(job.result, dict):
        out["result"] = job.result.get("facts")
    return JSON(out)


async def job_cancel(request):
    job = _studio(request).job(request.path_params["job"])
    job.cancel_event.set()
    return JSON(job.to_dict())


def _loop_job(request):
    job = _studio(request).job(request.path_params["job"])
    if job.kind == "loop" and job.status == "refused":
        raise LoopRefused(f"{job.error} (ask again with force)")
    if job.status != "done" or job.kind != "loop":
        raise v.BadRequest(f"job {job.id} has no loop ({job.status})")
    return job.result


async def job_motion(request):
    result = _loop_job(request)
    data = await run_in_threadpool(motion_payload, result["view"], {
        "name": "loop", "forced": result["facts"]["forced"]})
    return _bytes_answer(data)


async def job_file(request):
    """The loop as a file, made once per job and suffix (:class:`Downloads`) and streamed from disk: forty
    downloads of a large loop cost one file, not forty builds in memory."""
    result = _loop_job(request)
    suffix = _suffix(request)
    name = f"{_file_name(Path(result['take'].name).stem)}_loop"
    path = await run_in_threadpool(result["files"].get, name + suffix,
                                   lambda target: write_motion_file(result["report"], "loop", target))
    failed = [c["check"] for c in result["facts"]["failed_checks"]]
    if failed:  # forced: the file's name and a header say so
        return _file_answer(path, f"{name}.forced{suffix}", {"X-Mocycle-Failed-Checks": ", ".join(failed)})
    return _file_answer(path, name + suffix)


async def not_found(request, exc):
    return _error(404, f"no such page: {request.url.path[:80]}")


async def not_allowed(request, exc):
    if getattr(exc, "status_code", 500) == 405:
        return _error(405, f"{request.method} is not allowed on {request.url.path[:80]}")
    return _error(getattr(exc, "status_code", 500), getattr(exc, "detail", "error"))


ROUTES = [
    Route("/", index),
    Route("/api/takes", answers(list_takes)),
    Route("/api/options", answers(options)),
    Route("/api/takes/{id}/motion", answers(take_motion)),
    Route("/api/takes/{id}/loop", answers(loop), methods=["POST"]),
    Route("/api/takes/{id}/plane", answers(plane)),
    Route("/api/takes/{id}/relayout", answers(relayout), methods=["POST"]),
    Route("/api/takes/{id}/strokes", answers(stroke), methods=["POST"]),
    Route("/api/strokes/{stroke}/motion", answers(stroke_motion)),
    Route("/api/strokes/{stroke}.{suffix:str}", answers(stroke_file)),
    Route("/api/jobs/{job}", answers(job_status)),
    Route("/api/jobs/{job}", answers(job_cancel), methods=["DELETE"]),
    Route("/api/jobs/{job}/motion", answers(job_motion)),
    Route("/api/jobs/{job}/loop.{suffix:str}", answers(job_file)),
    Mount("/static", StaticFiles(directory=STATIC), name="static"),
]


@contextlib.asynccontextmanager
async def _lifespan(app):
    yield
    app.state.studio.analysis.shutdown()
    app.state.studio.interactive.shutdown()
    shutil.rmtree(app.state.studio.files, ignore_errors=True)


def create_app(paths=(), *, studio: Studio | None = None, amc_fps: float = tasks.AMC_FPS,
               limits: Limits | None = None, access: Access | None = None) -> Starlette:
    """The studio's ASGI app over the takes in ``paths`` (files or folders).

    ``access``: who may ask (the token, the address served; see :mod:`.guard`); by default a random token and
    127.0.0.1 on any port until the command binds its socket (``app.state.access.bind(host, port)``).
    """
    st = studio or Studio(paths, amc_fps=amc_fps, limits=limits)
    access = access or Access(max_body=st.limits.max_body)
    app = Starlette(routes=ROUTES, lifespan=_lifespan, middleware=[Middleware(Guard, access=access)],
                    exception_handlers={404: not_found, 405: not_allowed})
    app.state.studio = st
    app.state.access = access
    return app
