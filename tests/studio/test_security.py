"""The studio under attack (issue 30): every case of the issue, through Starlette's TestClient (the browser's
own view of it is in test_security_browser.py).

Cross-site requests, DNS rebinding, a server on the network, security headers; request bodies too large, too
deep, with numbers out of range or of the wrong type; memory held by jobs and strokes; links out of the served
folder, non-UTF-8 file names."""

from __future__ import annotations

import json
import os
import re
import time

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx")

from mocycle.studio import app as app_module  # noqa: E402
from mocycle.studio.app import Limits, create_app  # noqa: E402
from mocycle.studio.payload import unpack  # noqa: E402
from studio_harness import api_client  # noqa: E402


def wait(client, job_id, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        j = client.get(f"/api/jobs/{job_id}").json()
        if j["status"] not in ("queued", "running"):
            return j
        time.sleep(0.02)
    raise AssertionError(f"job {job_id} did not finish")


def analysed(client):
    for _ in range(1200):
        data = client.get("/api/takes").json()
        if data["done"] == data["total"]:
            return {t["name"]: t for t in data["takes"]}
        time.sleep(0.1)
    raise AssertionError("the library was not analysed")


@pytest.fixture(scope="module")
def client(hostile):
    with api_client(create_app([hostile])) as c:
        c.takes = analysed(c)
        yield c


@pytest.fixture(scope="module")
def walk(client):
    """The walk's id, its plane's keyframes and their markers."""
    tid = client.takes["walk.bvh"]["id"]
    header, arrays = unpack(client.get(f"/api/takes/{tid}/plane", params={"optimize": 0}).content)
    key = header["keyframes"]
    pts = arrays["points"].astype(float)
    return tid, key, pts[key].tolist(), pts


def held(client):
    return client.app.state.studio.held()


# ---------------------------------------------------------------- cross-site requests (issue 30, 1)
def test_a_cross_site_post_is_refused_and_starts_nothing(client, walk):
    tid = walk[0]
    before = held(client)["jobs"]
    url = f"/api/takes/{tid}/loop"
    no_token = {"X-Mocycle-Token": ""}
    body = '{"cycles": 20}'
    cases = [  # (headers, status, words in the message)
        ({**no_token, "Content-Type": "text/plain"}, 403, "token"),  # fetch no-cors, or a form enctype=text/plain
        ({**no_token, "Content-Type": "application/x-www-form-urlencoded"}, 403, "token"),
        ({**no_token, "Content-Type": "application/json"}, 403, "token"),
        ({"X-Mocycle-Token": "wrong", "Content-Type": "application/json"}, 403, "token"),
        ({"Content-Type": "text/plain"}, 415, "application/json"),  # the token but not JSON
        ({"Content-Type": "application/json", "Origin": "http://attacker.example"}, 403, "another origin"),
        ({"Content-Type": "application/json", "Origin": "null"}, 403, "another origin"),
        ({"Content-Type": "application/json", "Sec-Fetch-Site": "cross-site"}, 403, "another site"),
        ({"Content-Type": "application/json", "Sec-Fetch-Site": "same-site"}, 403, "another site"),
    ]
    for headers, status, words in cases:
        r = client.post(url, content=body, headers=headers)
        assert r.status_code == status and words in r.json()["error"], (headers, r.status_code, r.text)
    stroke = client.post(f"/api/takes/{tid}/strokes", content="{}", headers={**no_token, "Content-Type": "text/plain"})
    assert stroke.status_code == 403
    assert client.delete("/api/jobs/j1", headers=no_token).status_code == 403
    assert held(client)["jobs"] == before  # nothing was queued
    ok = client.post(url, json={"cycles": 2}, headers={"Origin": "http://127.0.0.1", "Sec-Fetch-Site": "same-origin"})
    assert ok.status_code == 202, ok.text  # the page's own request
    assert wait(client, ok.json()["id"])["status"] == "done"


def test_cross_site_reads_of_the_api_are_refused(client):
    r = client.get("/api/takes", headers={"Sec-Fetch-Site": "cross-site"})
    assert r.status_code == 403 and "walk.bvh" not in r.text
    assert client.get("/api/takes", headers={"Sec-Fetch-Site": "same-origin"}).status_code == 200


# ---------------------------------------------------------------- DNS rebinding (issue 30, 2)
def test_only_the_served_host_is_answered(hostile):
    app = create_app([hostile])
    app.state.access.bind("127.0.0.1", 8765)
    with api_client(app, base_url="http://127.0.0.1:8765") as c:
        for host in ("attacker.example", "attacker.example:8765", "127.0.0.1:9999", "localhost:1", "10.0.0.1:8765"):
            for path in ("/", "/api/takes", "/static/studio.js"):
                r = c.get(path, headers={"Host": host})
                assert r.status_code == 421 and "walk.bvh" not in r.text and "127.0.0.1:8765" in r.json()["error"]
        assert c.get("/api/takes", headers={"Host": "a:b:c"}).status_code == 400
        for host in ("127.0.0.1:8765", "localhost:8765", "LOCALHOST:8765", "[::1]:8765"):
            assert c.get("/api/takes", headers={"Host": host}).status_code == 200, host


# ---------------------------------------------------------------- security headers
def test_every_answer_has_the_security_headers(client, walk):
    page = client.get("/")
    for r in (page, client.get("/api/takes"), client.get("/static/studio.js"), client.get("/nope"),
              client.get("/api/takes", headers={"Host": "evil.example"}),
              client.post(f"/api/takes/{walk[0]}/loop", content="x", headers={"Content-Type": "text/plain"})):
        assert r.headers["x-frame-options"] == "DENY" and r.headers["x-content-type-options"] == "nosniff"
        assert r.headers["referrer-policy"] == "no-referrer"
        assert "frame-ancestors 'none'" in r.headers["content-security-policy"]
    csp = page.headers["content-security-policy"]
    nonce = re.search(r"'nonce-([^']+)'", csp).group(1)
    assert "unsafe-inline" not in csp and "unsafe-eval" not in csp and "script-src 'self'" in csp
    assert page.text.count("<script") == page.text.count(f'<script nonce="{nonce}"') == 2  # importmap, module
    assert f'content="{client.app.state.access.token}"' in page.text
    assert client.get("/").headers["content-security-policy"] != csp  # a nonce per answer
    assert client.get("/static/studio.js").headers["content-type"].startswith("text/javascript")


# ---------------------------------------------------------------- a server on the network (--host)
def test_a_network_server_needs_the_token_on_every_request(hostile):
    app = create_app([hostile])
    app.state.access.bind("0.0.0.0", 8765)
    token = app.state.access.token
    with api_client(app, base_url="http://192.168.1.5:8765", headers={"X-Mocycle-Token": ""}) as c:
        for path in ("/", "/api/takes", "/static/studio.js"):
            r = c.get(path)
            assert r.status_code == 403 and "token" in r.json()["error"] and "walk.bvh" not in r.text
        assert c.get("/", params={"token": "wrong"}).status_code == 403
        r = c.get("/", params={"token": token})
        cookie = r.headers["set-cookie"]
        assert r.status_code == 200 and "SameSite=Strict" in cookie and "HttpOnly" in cookie
        assert c.get("/static/studio.js").status_code == 200  # the cookie now carries it (the page's modules)
        c.cookies.clear()
        assert c.get("/api/takes", headers={"X-Mocycle-Token": token}).status_code == 200


def test_the_command_warns_and_prints_the_token_for_a_network_host(hostile):
    import signal
    import subprocess
    import sys

    import httpx

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    proc = subprocess.Popen([sys.executable, "-m", "mocycle", "studio", str(hostile / "walk.bvh"), "--no-browser",
                             "--port", "0", "--host", "0.0.0.0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)
    try:
        line = proc.stdout.readline()
        assert re.match(r"mocycle studio on http://0\.0\.0\.0:\d+/\?token=\S+ ", line), line + proc.stderr.read()
        warning = proc.stderr.readline()
        assert warning.startswith("warning: --host 0.0.0.0 serves your motion library to the network")
        url = line.split()[3]
        base = url.split("?")[0].replace("0.0.0.0", "127.0.0.1")
        assert httpx.get(base + "api/takes", timeout=30).status_code == 403
        with httpx.Client(timeout=30) as c:
            assert c.get(url.replace("0.0.0.0", "127.0.0.1")).status_code == 200
            assert c.get(base + "api/takes").json()["takes"][0]["name"] == "walk.bvh"  # by the cookie
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(30)


# ---------------------------------------------------------------- bounded memory (issue 30, 3)
def test_a_body_too_large_is_refused_before_it_is_read(hostile, walk):
    app = create_app([hostile], limits=Limits(max_body=1000))
    with api_client(app) as c:
        url = f"/api/takes/{walk[0]}/strokes"
        r = c.post(url, content=b"x", headers={"Content-Type": "application/json", "Content-Length": str(1 << 30)})
        assert r.status_code == 413 and "at most 1000" in r.json()["error"]

        def chunks():  # no Content-Length: streamed, cut off at the limit
            for _ in range(100):
                yield b" " * 100

        r = c.post(url, content=chunks(), headers={"Content-Type": "application/json"})
        assert r.status_code == 413 and "more than 1000 bytes" in r.json()["error"]
        assert c.post(url, content=b" " * 900 + b"{}", headers={"Content-Type": "application/json"}).status_code == 400


def test_a_stroke_too_long_is_refused_before_it_is_made(hostile, walk):
    tid, key, markers, pts = walk
    with api_client(create_app([hostile], limits=Limits(max_stroke_frames=600))) as c:
        r = c.post(f"/api/takes/{tid}/strokes", json={"keyframes": key, "markers": markers, "points": pts[:2].tolist(),
                                                      "times_s": [0, 60]})
        assert r.status_code == 400 and "3601 frames; at most 600" in r.json()["error"]
        assert len(c.app.state.studio.strokes) == 0


def _stroke(c, walk, n=60):
    tid, key, markers, pts = walk
    r = c.post(f"/api/takes/{tid}/strokes", json={"keyframes": key, "markers": markers, "points": pts[:n].tolist(),
                                                  "times_s": (np.arange(n) / 60).tolist(), "feet": "keep"})
    assert r.status_code == 200, r.text
    return r.json()["id"]


def test_strokes_are_evicted_least_recently_used_and_a_gone_one_is_410(hostile, walk):
    with api_client(create_app([hostile], limits=Limits(max_strokes=3))) as c:
        ids = [_stroke(c, walk) for _ in range(4)]
        assert c.get(f"/api/strokes/{ids[1]}.bvh").status_code == 200  # used: now the most recent
        ids.append(_stroke(c, walk))
        assert len(c.app.state.studio.strokes) == 3
        for gone in (ids[0], ids[2]):
            r = c.get(f"/api/strokes/{gone}/motion")
            assert r.status_code == 410 and f"stroke {gone} is gone" in r.json()["error"]
        assert c.get(f"/api/strokes/{ids[1]}/motion").status_code == 200
        assert c.get("/api/strokes/s999/motion").status_code == 404
    budget = 3 * 60 * 40 * 4 * 8  # about two 60-frame strokes of the 40-joint walk
    with api_client(create_app([hostile], limits=Limits(max_stroke_bytes=budget))) as c:
        for _ in range(6):
            _stroke(c, walk)
        s = c.app.state.studio.strokes
        assert 1 <= len(s) < 6 and s.bytes <= budget


@pytest.mark.slow  # 18 s of load: make test runs it, make check does not
def test_sixty_jobs_and_strokes_keep_what_is_held_bounded(hostile, walk):
    """A studio under load: 60 loop jobs and 60 strokes; what it holds stays at its limits."""
    limits = Limits(max_jobs_kept=5, max_strokes=5)
    with api_client(create_app([hostile], limits=limits)) as c:
        tid = walk[0]
        counts = []
        first = None
        for i in range(60):
            j = c.post(f"/api/takes/{tid}/loop", json={"cycles": 1 + i % 3})
            assert j.status_code == 202, j.text
            first = first or j.json()["id"]
            assert wait(c, j.json()["id"])["status"] == "done"
            _stroke(c, walk, n=30)
            counts.append(held(c))
        assert max(h["jobs"] for h in counts) <= 5 and max(h["strokes"] for h in counts) <= 5
        assert counts[-1]["job_bytes"] <= 1.5 * max(h["job_bytes"] for h in counts[4:10])  # flat, not growing
        r = c.get(f"/api/jobs/{first}/loop.bvh")
        assert r.status_code == 410 and "gone" in r.json()["error"]


def test_too_many_waiting_jobs_is_429_and_cancelled_ones_do_not_count(hostile, walk):
    with api_client(create_app([hostile], limits=Limits(max_pending=2))) as c:
        answers = [c.post(f"/api/takes/{walk[0]}/loop", json={"cycles": 5}) for _ in range(8)]
        codes = [r.status_code for r in answers]
        assert 429 in codes and codes[:2] == [202, 202], codes
        assert "at most 2" in answers[codes.index(429)].json()["error"]
        # the page cancels a loop a newer one supersedes: a cancelled job no longer counts
        for r in answers:
            if r.status_code == 202:
                c.delete(f"/api/jobs/{r.json()['id']}")
        assert [c.post(f"/api/takes/{walk[0]}/loop", json={}).status_code for _ in range(2)] == [202, 202]


# ---------------------------------------------------------------- strict validation (issue 30, robustness)
def test_hostile_bodies_get_one_400_naming_the_field(client, walk):
    tid, key, markers, pts = walk
    relayout = f"/api/takes/{tid}/relayout"
    stroke = {"keyframes": key, "markers": markers, "points": pts[:10].tolist(), "times_s": list(range(10))}
    before = held(client)["jobs"]
    cases = [  # (url, body or raw text, words in the one message)
        (relayout, "[" * 100_000, "nests too deep"),
        (relayout, '{"a":' * 100_000, "nests too deep"),
        (relayout, '{"keyframes": [NaN]}', "NaN"),
        (relayout, "[1, 2]", "must be a JSON object"),
        (relayout, b'{"a": "\xff"}', "not UTF-8"),
        (relayout, "not json", "not JSON"),
        (relayout, '{"keyframes": [' + "9" * 5000 + "]}", "not JSON"),
        (relayout, {"keyframes": [2**70, 1, 2], "markers": markers[:3]}, "keyframes[0]"),
        (relayout, {"keyframes": [-1, 1, 2], "markers": markers[:3]}, "keyframes[0] must be a frame number >= 0"),
        (relayout, {"keyframes": [0, 1, 10**9], "markers": markers[:3]}, "keyframes[2] must be a frame number"),
        (relayout, {"keyframes": [0, 1, 1e9], "markers": markers[:3]}, "keyframes[2] must be an integer"),
        (relayout, {"keyframes": [0, 1, True], "markers": markers[:3]}, "keyframes[2] must be an integer"),
        (relayout, {"keyframes": [5], "markers": markers[:1]}, "keyframes must hold 3 to"),
        (relayout, {"keyframes": [5, 5, 6], "markers": markers[:3]}, "distinct"),
        (relayout, {"keyframes": key, "markers": markers, "optimize": "no"}, "optimize must be true or false"),
        (relayout, {"keyframes": key, "markers": markers, "optimize": "maybe"}, "optimize must be true or false"),
        (relayout, {"keyframes": key, "markers": markers, "optimize": 1}, "optimize must be true or false"),
        (relayout, {"markers": markers}, "keyframes is missing"),
        (relayout, {"keyframes": key}, "markers is missing"),
        (relayout, {"keyframes": key, "markers": markers[:-1]}, "one [x, y] per keyframe"),
        (relayout, {"keyframes": key, "markers": [[0, "x"]] + markers[1:]}, "markers[0][1] must be a number"),
        (relayout, json.dumps({"keyframes": key, "markers": markers}).replace("[", "[[1e999, 0], ", 2).replace(
            "[[1e999, 0], ", "[", 1), "markers[0][0] must be a finite number"),
        (relayout, {"keyframes": key, "markers": markers, "extra": 1}, "unknown field 'extra'"),
        (f"/api/takes/{tid}/strokes", {**stroke, "times_s": [0] * 9}, "one time per point"),
        (f"/api/takes/{tid}/strokes", {**stroke, "times_s": list(range(10))[::-1]}, "must not decrease"),
        (f"/api/takes/{tid}/strokes", {**stroke, "points": [[0, 0, 0]] * 10}, "points[0] must be a point"),
        (f"/api/takes/{tid}/strokes", {**stroke, "feet": "sideways"}, "feet"),
        (f"/api/takes/{tid}/strokes", {**stroke, "times_s": None}, "times_s must be a list"),
        (f"/api/takes/{tid}/loop", {"force": "yes"}, "force must be true or false"),
        (f"/api/takes/{tid}/loop", {"cycles": 2**70}, "cycles"),
        (f"/api/takes/{tid}/loop", {"cycles": [1]}, "cycles must be a word or a number"),
        (f"/api/takes/{tid}/loop", {"method": "nonsense"}, "method must be one of"),
    ]
    for url, body, words in cases:
        if isinstance(body, (dict, list)):
            r = client.post(url, json=body)
        else:
            r = client.post(url, content=body, headers={"Content-Type": "application/json"})
        assert r.status_code == 400, (body if len(str(body)) < 200 else str(body)[:200], r.status_code, r.text)
        assert words in r.json()["error"], (words, r.json())
    assert held(client)["jobs"] == before  # refused before any job ran
    for query, words in ((("optimize", "no"),), "optimize must be 0, 1"), ((("bogus", "1"),), "unknown field"), \
            ((("ratio", "nan"),), "ratio"), ((("projection", "umap"),), "projection"):
        r = client.get(f"/api/takes/{tid}/plane", params=dict(query))
        assert r.status_code == 400 and words in r.json()["error"], r.text


def test_not_found_is_explicit_not_any_key_error(client):
    assert not hasattr(app_module, "_guard")
    for path, words in (("/api/takes/t99/motion", "no take t99"), ("/api/takes/x/motion", "no take"),
                        ("/api/jobs/j99999/motion", "no job"), ("/api/strokes/s77.bvh", "no stroke"),
                        ("/api/jobs/zz", "no job"), ("/nope", "no such page")):
        r = client.get(path)
        assert r.status_code == 404 and words in r.json()["error"], (path, r.text)
    r = client.put("/api/takes")
    assert r.status_code == 405 and r.json()["error"].startswith("PUT is not allowed")


# ---------------------------------------------------------------- files in the served folder
def test_a_link_out_of_the_folder_is_not_read(client):
    passwd = client.takes["passwd.bvh"]
    assert passwd["status"] == "refused" and "outside the served folder" in passwd["error"]
    secret = open("/etc/passwd").readline().strip()
    r = client.get(f"/api/takes/{passwd['id']}/motion")
    assert r.status_code == 400 and "outside the served folder" in r.json()["error"]
    text = client.get("/api/takes").text
    assert secret[:20] not in text and secret[:20] not in r.text and "root:" not in r.text


def test_a_non_utf8_file_name_is_listed_escaped_and_served(client):
    take = client.takes["bad\\xffname.bvh"]
    assert take["status"] == "done" and take["path"].endswith("bad\\xffname.bvh")
    header, arrays = unpack(client.get(f"/api/takes/{take['id']}/motion").content)
    assert header["name"] == "bad\\xffname.bvh" and arrays["positions"].shape[0] == 120
    assert client.takes["notbvh.bvh"]["status"] == "failed"
    assert client.takes['<img src=x onerror="window.__pwned=1">.bvh']["status"] == "done"  # a name is data
