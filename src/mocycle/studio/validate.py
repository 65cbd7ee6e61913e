"""The studio's requests checked in one place: JSON bodies and query strings become plain values or one
:class:`BadRequest` naming the field, before any work starts.

Every check here is explicit (no schema library): a body is parsed with a bounded depth, numbers must be
JSON numbers (``true`` is not ``1``, ``1e9`` is not a keyframe), booleans JSON booleans, lists have bounded
lengths, keyframes lie within the take.  The HTTP error the handlers raise is here too: :class:`HTTPProblem`
with its status, and :class:`BadRequest` (400) for the checks.
"""

from __future__ import annotations

import json
import math
import re
from http import HTTPStatus

from ..errors import MocycleError
from ..tasks.spec import SPECS


class HTTPProblem(MocycleError):
    """A request the studio answers with ``status`` and the message (JSON ``{"error": message}``): one class,
    the status named by :class:`http.HTTPStatus` where it is raised (``NOT_FOUND``: no such take, job, stroke
    or download; ``REQUEST_TIMEOUT``: a body too slow; ``GONE``: evicted; ``REQUEST_ENTITY_TOO_LARGE``;
    ``TOO_MANY_REQUESTS``: too many jobs; ``SERVICE_UNAVAILABLE``: a take still being read)."""

    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST):
        super().__init__(message)
        self.status = int(status)


class BadRequest(HTTPProblem):
    """400: the request itself is wrong (what every check here raises)."""


#: most keyframes a request may name; most samples a stroke may have (a 10-minute stroke at 120 Hz is 72,000)
MAX_KEYFRAMES = 4096
MAX_STROKE_POINTS = 100_000
#: most cycles a loop job repeats (the page's form offers 1 to this)
MAX_CYCLES = 100


def form_fields(task: str) -> tuple[str, ...]:
    """The fields of a task's form: what its spec names for the studio (each value is checked again by the
    task's Options)."""
    return SPECS[task].studio

_ID = {"take": re.compile(r"t\d{1,9}"), "job": re.compile(r"j\d{1,9}"), "stroke": re.compile(r"s\d{1,9}")}


def _no_constant(name: str):
    raise BadRequest(f"the request body holds {name}, which is not a JSON number")


class _Written(float):
    """A JSON number beyond float's range (``1e400``): infinite, but shown as it was written (also by the
    tasks' option checks, which quote ``repr``)."""

    text: str

    def __repr__(self) -> str:
        return self.text

    __str__ = __repr__


def _float(text: str) -> float:
    number = float(text)
    if math.isfinite(number):
        return number
    out = _Written(number)
    out.text = text
    return out


def parse_body(raw: bytes) -> dict:
    """The body as a JSON object: UTF-8, not nested beyond the parser's recursion limit, no NaN or Infinity
    (each a :class:`BadRequest`)."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise BadRequest("the request body is not UTF-8 text") from None
    try:
        body = json.loads(text, parse_constant=_no_constant, parse_float=_float)
    except RecursionError:
        raise BadRequest("the request body nests too deep") from None
    except ValueError as exc:  # JSONDecodeError, an integer of too many digits
        raise BadRequest(f"the request body is not JSON: {exc}") from None
    if not isinstance(body, dict):
        raise BadRequest("the request body must be a JSON object")
    return body


def path_id(kind: str, value: str) -> str:
    """A take, job or stroke id from the URL (``t3``, ``j12``, ``s4``), else 404."""
    if not _ID[kind].fullmatch(value):
        raise HTTPProblem(f"no {kind} {value[:40]!r}", HTTPStatus.NOT_FOUND)
    return value


def _known(body: dict, allowed) -> None:
    extra = sorted(set(body) - set(allowed))
    if extra:
        raise BadRequest(f"unknown field {extra[0][:40]!r} (known: {', '.join(allowed)})")


def _required(body: dict, name: str):
    if name not in body:
        raise BadRequest(f"{name} is missing")
    return body[name]


def boolean(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise BadRequest(f"{name} must be true or false; got {_show(value)}")
    return value


def _show(value) -> str:
    """``value`` in a message: short JSON, or what it is when it is a list or an object."""
    if isinstance(value, list):
        return f"a list of {len(value)} items"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, _Written):
        return f"{value.text[:37]} (beyond the largest number, about 1.8e308)"
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _number(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BadRequest(f"{name} must be a number; got {_show(value)}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise BadRequest(f"{name} must be a finite number; got {_show(value)}")
    return number


def _list(name: str, value, low: int, high: int) -> list:
    if not isinstance(value, list):
        raise BadRequest(f"{name} must be a list; got {_show(value)}")
    if not low <= len(value) <= high:
        raise BadRequest(f"{name} must hold {low} to {high} items; got {len(value)}")
    return value


def keyframes(value, n_frames: int | None, *, low: int = 3) -> list[int]:
    """Distinct frame numbers in ``[0, n_frames)``, JSON integers, at least ``low``."""
    items = _list("keyframes", value, low, MAX_KEYFRAMES)
    out = []
    for i, k in enumerate(items):
        if isinstance(k, bool) or not isinstance(k, int):
            raise BadRequest(f"keyframes[{i}] must be an integer frame number; got {_show(k)}")
        if k < 0 or (n_frames is not None and k >= n_frames):
            top = "" if n_frames is None else f" < {n_frames}, the take's frames"
            raise BadRequest(f"keyframes[{i}] must be a frame number >= 0{top}; got {_show(k)}")
        out.append(k)
    if len(set(out)) != len(out):
        raise BadRequest("keyframes must be distinct frames")
    return out


def points(name: str, value, low: int, high: int) -> list[list[float]]:
    """A list of ``[x, y]`` finite numbers."""
    out = []
    for i, p in enumerate(_list(name, value, low, high)):
        if not isinstance(p, list) or len(p) != 2:
            raise BadRequest(f"{name}[{i}] must be a point [x, y]; got {_show(p)}")
        out.append([_number(f"{name}[{i}][0]", p[0]), _number(f"{name}[{i}][1]", p[1])])
    return out


def _option_text(body: dict, fields) -> dict:
    """The named task options present (words or numbers; the task's Options check their values)."""
    out = {}
    for name in fields:
        value = body.get(name)
        if value is None or value == "":
            continue
        if isinstance(value, bool) or not isinstance(value, (str, int)):
            raise BadRequest(f"{name} must be a word or a number; got {_show(value)}")
        if isinstance(value, str) and len(value) > 64:
            raise BadRequest(f"{name} is too long ({len(value)} characters)")
        out[name] = value
    return out


def loop_request(body: dict) -> tuple[dict, bool]:
    """``POST /api/takes/{id}/loop``: the loop's options and ``force``; ``cycles`` at most :data:`MAX_CYCLES`
    (the studio's bound: the task's own is the output's length, found only after the cycle is made)."""
    _known(body, (*form_fields("loop"), "force"))
    options = _option_text(body, form_fields("loop"))
    if "cycles" in options:
        n = options["cycles"]
        if isinstance(n, str) and n.strip().isdigit() and len(n.strip()) < 6:
            n = int(n)
        if not isinstance(n, int) or not 1 <= n <= MAX_CYCLES:
            raise BadRequest(f"cycles must be an integer from 1 to {MAX_CYCLES}; got {_show(options['cycles'])}")
        options["cycles"] = n
    return options, boolean("force", body.get("force", False))


def _keyed_markers(body: dict, n_frames: int) -> tuple[list[int], list[list[float]]]:
    key = keyframes(_required(body, "keyframes"), n_frames)
    markers = points("markers", _required(body, "markers"), 0, MAX_KEYFRAMES)
    if len(markers) != len(key):
        raise BadRequest(f"markers must hold one [x, y] per keyframe ({len(key)}); got {len(markers)}")
    return key, markers


def relayout_request(body: dict, n_frames: int) -> tuple[list[int], list[list[float]], bool]:
    """``POST /api/takes/{id}/relayout``: keyframes within the take's ``n_frames``, a marker each, optimize."""
    _known(body, ("keyframes", "markers", "optimize"))
    key, markers = _keyed_markers(body, n_frames)
    return key, markers, boolean("optimize", body.get("optimize", True))


def stroke_request(body: dict, n_frames: int, frame_time: float, max_frames: int) -> dict:
    """``POST /api/takes/{id}/strokes``: the stroke (as ``tasks.author`` takes it) and its options; the
    animation it makes (one frame per ``frame_time`` of its duration) must be at most ``max_frames``."""
    _known(body, ("keyframes", "markers", "points", "times_s", *form_fields("author")))
    key, markers = _keyed_markers(body, n_frames)
    pts = points("points", _required(body, "points"), 1, MAX_STROKE_POINTS)
    times = [_number(f"times_s[{i}]", t) for i, t in
             enumerate(_list("times_s", _required(body, "times_s"), 1, MAX_STROKE_POINTS))]
    if len(times) != len(pts):
        raise BadRequest(f"times_s must hold one time per point ({len(pts)}); got {len(times)}")
    if any(b < a for a, b in zip(times, times[1:], strict=False)):
        raise BadRequest("times_s must not decrease")
    frames = math.floor((times[-1] - times[0]) / frame_time + 1e-9) + 1
    if frames > max_frames:
        raise BadRequest(f"the stroke would make {frames} frames; at most {max_frames} "
                         f"({max_frames * frame_time:.0f} s at the take's frame rate)")
    return {"stroke": {"keyframes": key, "markers": markers, "points": pts, "times_s": times},
            "options": _option_text(body, form_fields("author"))}


def plane_query(query) -> dict:
    """``GET /api/takes/{id}/plane?...``: the plane's options as ``tasks.project.Options`` takes them."""
    query = {k: v for k, v in query.items() if k != "token"}  # a network server's token (see guard.py)
    _known(query, form_fields("project"))
    params = {k: v for k, v in query.items() if k != "optimize"}
    for name, value in params.items():
        if len(value) > 64:
            raise BadRequest(f"{name} is too long ({len(value)} characters)")
    if "optimize" in query:
        flag = query["optimize"]
        if flag not in ("0", "1", "true", "false"):
            raise BadRequest(f"optimize must be 0, 1, true or false; got {flag[:40]!r}")
        params["optimize"] = flag in ("1", "true")
    return params
