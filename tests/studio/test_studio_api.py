"""The studio's JSON API (Starlette's TestClient): library, payloads, loops, the plane, strokes, re-layout."""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx")

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # starlette 1.x suggests httpx2 over httpx; both work
    from starlette.testclient import TestClient  # noqa: E402

from mocycle.io.bvh import parse_bvh  # noqa: E402
from mocycle.studio.app import create_app  # noqa: E402
from mocycle.studio.payload import pack, unpack  # noqa: E402


def wait(client, job, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        j = client.get(f"/api/jobs/{job['id']}").json()
        if j["status"] in ("done", "failed", "cancelled"):
            return j
        time.sleep(0.05)
    raise AssertionError(f"job {job} did not finish")


@pytest.fixture(scope="module")
def client(library):
    with TestClient(create_app([library])) as c:
        yield c


def test_payload_round_trip():
    a = np.arange(24, dtype=np.float32).reshape(2, 4, 3)
    header, arrays = unpack(pack({"x": 1}, {"a": a, "b": np.ones(3)}))
    assert header["x"] == 1 and list(header["blocks"]) == ["a", "b"]
    np.testing.assert_array_equal(arrays["a"], a)
    assert arrays["b"].dtype == np.float32


def test_library_is_analysed_in_the_background(client):
    t0 = time.monotonic()
    while True:
        data = client.get("/api/takes").json()
        if data["done"] == data["total"] or time.monotonic() - t0 > 120:
            break
        time.sleep(0.1)
    takes = {t["name"]: t for t in data["takes"]}
    assert set(takes) == {"walk.bvh", "wander.bvh"} and data["done"] == 2
    walk = takes["walk.bvh"]
    assert walk["status"] == "done" and walk["facts"]["frames"] == 240 and walk["facts"]["fps"] == 60
    assert len(walk["loops"]) == 1
    loop = walk["loops"][0]
    assert loop["period_s"] == pytest.approx(1.0, rel=0.05)
    assert loop["seam_pose"] is not None and loop["skate"] is not None
    assert takes["wander.bvh"]["loops"] == [] and "no periodic motion" in takes["wander.bvh"]["reason"]


def test_motion_payload_has_world_positions(client):
    tid = client.get("/api/takes").json()["takes"][0]["id"]
    r = client.get(f"/api/takes/{tid}/motion")
    assert r.headers["content-type"] == "application/octet-stream"
    header, arrays = unpack(r.content)
    P = len(header["parents"])
    assert arrays["positions"].shape == (header["frames"], P, 3)
    assert header["up"] == [0.0, 1.0, 0.0] and header["height"] > 0
    assert len(r.content) < 1.2 * arrays["positions"].nbytes + 4000  # binary, not text


def test_loop_job_with_options_and_its_bvh(client):
    tid = next(t["id"] for t in client.get("/api/takes").json()["takes"] if t["name"] == "walk.bvh")
    job = client.post(f"/api/takes/{tid}/loop", json={"method": "centroid", "root": "motion", "cycles": 2}).json()
    j = wait(client, job)
    assert j["status"] == "done", j
    assert j["result"]["options"]["method"] == "centroid" and len(j["result"]["phase"]) == 240
    header, arrays = unpack(client.get(f"/api/jobs/{j['id']}/motion").content)
    assert header["frames"] == j["result"]["frames_out"] == 2 * j["result"]["loop"]["cycle_frames"]
    bvh = parse_bvh(client.get(f"/api/jobs/{j['id']}/loop.bvh").text)
    assert bvh.n_frames == header["frames"]
    bad = client.post(f"/api/takes/{tid}/loop", json={"method": "nonsense"})
    assert bad.status_code == 400 and "method" in bad.json()["error"]


def test_plane_stroke_export_and_relayout(client):
    tid = next(t["id"] for t in client.get("/api/takes").json()["takes"] if t["name"] == "wander.bvh")
    header, arrays = unpack(client.get(f"/api/takes/{tid}/plane", params={"ratio": 0.05, "optimize": 1}).content)
    key = header["keyframes"]
    pts = arrays["points"].astype(float)
    assert arrays["key_rotations"].shape == (len(key), header["joints"], 9) and pts.shape == (240, 2)
    body = {"keyframes": key, "markers": pts[key].tolist(), "points": pts[:120].tolist(),
            "times_s": (np.arange(120) / 60).tolist(), "feet": "keep"}
    s = client.post(f"/api/takes/{tid}/strokes", json=body).json()
    assert s["frames"] == 120 and s["server_ms"] > 0
    motion = parse_bvh(client.get(f"/api/strokes/{s['id']}.bvh").text)
    assert motion.n_frames == 120
    job = client.post(f"/api/takes/{tid}/relayout", json={"keyframes": key, "markers": (pts[key] * 1.2).tolist()})
    j = wait(client, job.json())
    assert j["status"] == "done" and j["result"]["error_after"] <= j["result"]["error_before"]
    np.testing.assert_allclose(np.array(j["result"]["points"])[key], pts[key] * 1.2, atol=1e-5)


def test_a_newer_relayout_cancels_the_older(client):
    tid = client.get("/api/takes").json()["takes"][0]["id"]
    header, arrays = unpack(client.get(f"/api/takes/{tid}/plane").content)
    key, pts = header["keyframes"], arrays["points"].astype(float)
    first = client.post(f"/api/takes/{tid}/relayout", json={"keyframes": key, "markers": pts[key].tolist()}).json()
    second = client.post(f"/api/takes/{tid}/relayout", json={"keyframes": key, "markers": pts[key].tolist()}).json()
    assert wait(client, first)["status"] in ("cancelled", "done")  # done when it finished before the second came
    assert wait(client, second)["status"] == "done"
    assert client.delete(f"/api/jobs/{second['id']}").json()["status"] == "done"


def test_errors_are_json(client):
    assert client.get("/api/takes/nope/motion").status_code == 404
    assert client.get("/api/strokes/s999.bvh").status_code == 404
    tid = client.get("/api/takes").json()["takes"][0]["id"]
    r = client.post(f"/api/takes/{tid}/strokes", json={"keyframes": [0, 1, 2]})
    assert r.status_code == 400 and "missing" in r.json()["error"]
    assert client.get(f"/api/takes/{tid}/plane", params={"projection": "umap"}).status_code == 400


def test_options_schema_for_the_forms(client):
    o = client.get("/api/options").json()
    assert "centroid" in o["loop"]["properties"]["method"]["enum"]
    assert "tsne" in o["plane"]["properties"]["projection"]["enum"]


def _env():
    import os
    import sys

    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}


def test_the_command_serves_the_library_and_stops_on_sigterm(library):
    import signal
    import subprocess
    import sys

    import httpx

    proc = subprocess.Popen([sys.executable, "-m", "mocycle", "studio", str(library), "--no-browser", "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
    try:
        line = proc.stdout.readline()
        assert line.startswith("mocycle studio on http://127.0.0.1:"), line + proc.stderr.read()
        url = line.split()[3]
        assert {t["name"] for t in httpx.get(url + "api/takes", timeout=30).json()["takes"]} == {"walk.bvh",
                                                                                                 "wander.bvh"}
        assert 'data-testid="plane"' in httpx.get(url, timeout=30).text
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(30)


def test_the_command_refuses_what_it_cannot_read(tmp_path):
    import subprocess
    import sys

    (tmp_path / "notes.txt").write_text("x")
    cases = ((tmp_path / "missing", "no such file or folder"), (tmp_path / "notes.txt", "not a motion file"),
             (tmp_path, "no motion files"))
    for arg, message in cases:
        r = subprocess.run([sys.executable, "-m", "mocycle", "studio", str(arg), "--no-browser"], capture_output=True,
                           text=True, env=_env())
        assert r.returncode == 1 and message in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_report_of_a_take_without_loop_and_bad_outputs(library, tmp_path):
    import subprocess
    import sys

    out = tmp_path / "wander.html"
    r = subprocess.run([sys.executable, "-m", "mocycle", "report", str(library / "wander.bvh"), "-o", str(out)],
                       capture_output=True, text=True, env=_env())
    assert r.returncode == 0 and "warning: no loop in the report: no periodic motion" in r.stderr, r.stderr
    import json

    text = out.read_text()
    data = json.loads(text.split('<script id="report-data" type="application/json">')[1].split("</script>")[0])
    assert "loop" not in data and data["reason"].startswith("no periodic motion") and data["take"]
    bad = subprocess.run([sys.executable, "-m", "mocycle", "report", str(library / "walk.bvh"), "-o",
                          str(tmp_path / "r.txt")], capture_output=True, text=True, env=_env())
    assert bad.returncode == 1 and "must name a .html or .htm file" in bad.stderr
    assert not (tmp_path / "r.txt").exists()
