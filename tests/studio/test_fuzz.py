"""A short property-based fuzz of the studio's API (hypothesis): any JSON body, any field replaced by any JSON
value, any path and method, any of the headers that matter, never gets a 500 and never leaves the server
holding more than its limits.  ``benchmarks/studio_fuzz.py`` runs the long version against a real server."""

from __future__ import annotations

import os

import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx")
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from mocycle import write  # noqa: E402
from mocycle.datasets import synthetic_walk  # noqa: E402
from mocycle.studio.app import Limits, create_app  # noqa: E402
from mocycle.studio.jobs import LIVE_FACTOR  # noqa: E402
from mocycle.studio.payload import unpack  # noqa: E402
from studio_harness import api_client  # noqa: E402

EXAMPLES = int(os.environ.get("MOCYCLE_STUDIO_FUZZ_EXAMPLES", "100"))
LIMITS = Limits(max_jobs_kept=4, max_strokes=4, max_pending=3)
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

numbers = st.one_of(st.integers(), st.integers(min_value=-(2**80), max_value=2**80), st.floats(allow_nan=False,
                    allow_infinity=False), st.sampled_from([0, -1, 1, 2**70, 10**9, 1e9, 0.5]))
scalars = st.one_of(st.none(), st.booleans(), numbers, st.text(max_size=20),
                    st.sampled_from(["no", "maybe", "true", "1", "keep", "lock", "motion", "pca"]))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=8),
                                                                                           inner, max_size=4),
                      max_leaves=20)
FIELDS = ["keyframes", "markers", "points", "times_s", "optimize", "force", "method", "model", "root", "feet",
          "cycles", "plant"]


@pytest.fixture(scope="module")
def fuzzed(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    write(synthetic_walk(n_frames=120).motion, folder / "walk.bvh")
    with api_client(create_app([folder], limits=LIMITS), raise_server_exceptions=False) as c:
        header, arrays = unpack(c.get("/api/takes/t0/plane", params={"optimize": 0}).content)
        key = header["keyframes"]
        pts = arrays["points"].astype(float)
        c.valid = {"keyframes": key, "markers": pts[key].tolist(), "points": pts[:20].tolist(),
                   "times_s": [i / 60 for i in range(20)]}
        yield c


def check(client, r):
    assert r.status_code < 500, (r.request.method, r.request.url, r.text[:300])
    h = client.app.state.studio.held()
    # kept, plus those not reached yet (cancelled ones included: LIVE_FACTOR times the pending limit)
    assert h["jobs"] <= LIMITS.max_jobs_kept + LIVE_FACTOR * LIMITS.max_pending and h["strokes"] <= LIMITS.max_strokes


@FUZZ
@given(route=st.sampled_from(["loop", "relayout", "strokes"]), body=values)
def test_any_json_body(fuzzed, route, body):
    check(fuzzed, fuzzed.post(f"/api/takes/t0/{route}", json=body))


@FUZZ
@given(route=st.sampled_from(["relayout", "strokes"]), changes=st.dictionaries(st.sampled_from(FIELDS), values,
                                                                               min_size=1, max_size=3),
       drop=st.lists(st.sampled_from(FIELDS), max_size=2))
def test_a_valid_body_with_fields_changed(fuzzed, route, changes, drop):
    body = {**fuzzed.valid, **changes}
    for name in drop:
        body.pop(name, None)
    if route == "relayout":
        body = {k: v for k, v in body.items() if k not in ("points", "times_s")}
    check(fuzzed, fuzzed.post(f"/api/takes/t0/{route}", json=body))


@FUZZ
@given(raw=st.one_of(st.binary(max_size=200), st.text(max_size=200).map(str.encode),
                     st.integers(1, 5000).map(lambda n: b"[" * n), st.integers(1, 5000).map(lambda n: b'{"a":' * n)))
def test_any_raw_body(fuzzed, raw):
    check(fuzzed, fuzzed.post("/api/takes/t0/strokes", content=raw, headers={"Content-Type": "application/json"}))


@FUZZ
@given(method=st.sampled_from(["GET", "POST", "DELETE", "PUT", "HEAD", "OPTIONS"]),
       path=st.one_of(st.sampled_from(["/api/takes/{}/motion", "/api/takes/{}/plane", "/api/jobs/{}",
                                       "/api/jobs/{}/motion", "/api/jobs/{}/loop.bvh", "/api/strokes/{}.glb",
                                       "/api/strokes/{}/motion", "/static/{}", "/{}"]),
                      st.just("/api/takes/t0/plane?{}")),
       part=st.one_of(st.sampled_from(["t0", "t1", "j1", "j0", "s1", "..", "%2e%2e/app.py", "ratio=nan",
                                       "optimize=maybe", "projection=x&ratio=2"]),
                      st.text(alphabet=st.characters(min_codepoint=33, max_codepoint=126, exclude_characters="/?#"),
                              max_size=12)))
def test_any_path_and_method(fuzzed, method, path, part):
    check(fuzzed, fuzzed.request(method, path.format(part)))


@FUZZ
@given(host=st.sampled_from(["127.0.0.1", "attacker.example", "localhost:1", "[::1]", "", "a:b:c", "x" * 300]),
       origin=st.sampled_from([None, "http://127.0.0.1", "http://attacker.example", "null"]),
       site=st.sampled_from([None, "same-origin", "cross-site", "same-site", "none"]),
       kind=st.sampled_from(["application/json", "text/plain", "multipart/form-data", ""]),
       token=st.sampled_from([None, "wrong", ""]), length=st.sampled_from([None, "abc", "-1", str(1 << 40)]))
def test_any_headers(fuzzed, host, origin, site, kind, token, length):
    headers = {"Host": host, "Origin": origin, "Sec-Fetch-Site": site, "Content-Type": kind}
    if token is not None:
        headers["X-Mocycle-Token"] = token
    if length is not None:
        headers["Content-Length"] = length
    r = fuzzed.post("/api/takes/t0/loop", content=b'{"cycles": 2}',
                    headers={k: v for k, v in headers.items() if v is not None})
    check(fuzzed, r)
    if r.status_code == 202:  # only the page's own request starts work
        assert host in ("127.0.0.1", "[::1]") and origin in (None, f"http://{host}") and token is None
        assert site in (None, "same-origin") and kind == "application/json" and length is None
