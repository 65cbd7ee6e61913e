"""The studio's JSON API (Starlette's TestClient): library, payloads, loops, the plane, strokes, re-layout."""

from __future__ import annotations

import time

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("httpx")


from mocycle.io.bvh import parse_bvh  # noqa: E402
from mocycle.studio.app import create_app  # noqa: E402
from mocycle.studio.payload import pack, unpack  # noqa: E402
from studio_harness import api_client  # noqa: E402


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
    with api_client(create_app([library])) as c:
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
    assert takes["wander.bvh"]["loops"] == [] and "no repeating motion" in takes["wander.bvh"]["reason"]


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
    assert j["result"]["frames_out"] == 2 * j["result"]["loop"]["cycle_frames"] and not j["result"]["forced"]
    header, arrays = unpack(client.get(f"/api/jobs/{j['id']}/motion").content)
    assert header["frames"] == 240 and not header["forced"]  # the viewer's loop: one frame per take frame
    r = client.get(f"/api/jobs/{j['id']}/loop.bvh")
    assert 'filename="walk_loop.bvh"' in r.headers["content-disposition"]
    assert parse_bvh(r.text).n_frames == j["result"]["frames_out"]  # as mocycle loop writes it
    bad = client.post(f"/api/takes/{tid}/loop", json={"method": "nonsense"})
    assert bad.status_code == 400 and "method" in bad.json()["error"]


def _glb_clip(data: bytes, tmp_path):
    """The one animation of a GLB file: its name and duration (seconds, its last key time)."""
    pygltflib = pytest.importorskip("pygltflib")
    path = tmp_path / "x.glb"
    path.write_bytes(data)
    gl = pygltflib.GLTF2().load(str(path))
    (anim,) = gl.animations
    times = gl.accessors[anim.samplers[0].input]
    return anim.name, times.max[0]


def test_loop_and_authored_animation_download_as_glb(client, tmp_path):
    """The GLB the studio gives is what ``mocycle loop -o walk_loop.glb`` writes: clip ``walk_loop``, closing
    frame included, so the clip lasts cycles × cycle frames / fps."""
    tid = next(t["id"] for t in client.get("/api/takes").json()["takes"] if t["name"] == "walk.bvh")
    j = wait(client, client.post(f"/api/takes/{tid}/loop", json={"root": "motion", "cycles": 3}).json())
    assert j["status"] == "done", j
    r = client.get(f"/api/jobs/{j['id']}/loop.glb")
    assert r.status_code == 200 and r.headers["content-type"] == "model/gltf-binary" and r.content[:4] == b"glTF"
    assert 'filename="walk_loop.glb"' in r.headers["content-disposition"]
    name, duration = _glb_clip(r.content, tmp_path)
    assert name == "walk_loop"
    assert duration == pytest.approx(3 * j["result"]["loop"]["cycle_frames"] / 60, abs=1e-4)
    assert client.get(f"/api/jobs/{j['id']}/loop.fbx").status_code == 404
    wander = next(t["id"] for t in client.get("/api/takes").json()["takes"] if t["name"] == "wander.bvh")
    header, arrays = unpack(client.get(f"/api/takes/{wander}/plane", params={"optimize": 0}).content)
    key, pts = header["keyframes"], arrays["points"].astype(float)
    s = client.post(f"/api/takes/{wander}/strokes", json={
        "keyframes": key, "markers": pts[key].tolist(), "points": pts[:90].tolist(),
        "times_s": (np.arange(90) / 60).tolist(), "feet": "keep"}).json()
    r = client.get(f"/api/strokes/{s['id']}.glb")
    assert r.status_code == 200 and f'filename="wander_authored_{s["id"]}.glb"' in r.headers["content-disposition"]
    name, duration = _glb_clip(r.content, tmp_path)
    assert name == f"wander_authored_{s['id']}" and duration == pytest.approx((s["frames"] - 1) / 60, abs=1e-4)


def test_the_viewers_loop_is_in_step_with_the_take_and_walks_on(client):
    """The loop the viewer plays: at take frame f the cycle frame of the take's phase there (so an overlay
    shows differences, not an offset), in its pass of the cycle repeated with root motion, placed at the take."""
    from mocycle import read

    take = next(t for t in client.get("/api/takes").json()["takes"] if t["name"] == "walk.bvh")
    j = wait(client, client.post(f"/api/takes/{take['id']}/loop", json={"root": "motion"}).json())
    _, arrays = unpack(client.get(f"/api/jobs/{j['id']}/motion").content)
    loop = arrays["positions"].astype(float)
    walk = read(take["path"])
    pos = walk.world_positions(end_sites=True)
    t = walk.travel_joint

    def pose_gap(a, b):  # mean distance of the points about the travel joint
        return np.linalg.norm((a - a[:, t:t + 1]) - (b - b[:, t:t + 1]), axis=2).mean()

    period = j["result"]["loop"]["cycle_frames"]
    aligned = pose_gap(loop, pos)
    for off in (period // 4, period // 2):  # a loop out of step by a quarter or half a cycle looks different
        assert aligned < 0.2 * pose_gap(np.roll(loop, off, axis=0), pos)
    frames = np.array(j["result"]["view"]["loop_frame"])
    assert frames.shape == (240,) and np.all((frames >= 0) & (frames < period))
    steps = np.diff(frames)
    assert np.all((np.abs(steps - 1) < 0.3) | (steps < -period + 2))  # one cycle frame per frame, wrapping
    travel = np.linalg.norm(loop[-1, t] - loop[0, t])
    assert travel > 0.8 * np.linalg.norm(pos[-1, t] - pos[0, t])  # walks on with its root motion
    assert np.linalg.norm(loop[:, t] - pos[:, t], axis=1).max() < 0.1 * take_height(pos)


def take_height(pos):
    return np.ptp(pos[..., 1])


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
    assert r.returncode == 0 and "warning: no loop in the report: no repeating motion" in r.stderr, r.stderr
    import json

    text = out.read_text()
    data = json.loads(text.split('<script id="report-data" type="application/json">')[1].split("</script>")[0])
    assert "loop" not in data and data["reason"].startswith("no repeating motion") and data["take"]
    bad = subprocess.run([sys.executable, "-m", "mocycle", "report", str(library / "walk.bvh"), "-o",
                          str(tmp_path / "r.txt")], capture_output=True, text=True, env=_env())
    assert bad.returncode == 1 and "must name a .html or .htm file" in bad.stderr
    assert not (tmp_path / "r.txt").exists()
