"""The studio and files that lie (issue 36): no take is held hostage by one file (a glTF whose buffer is a FIFO, one
of type-confused fields, a bug in the analysis: each ends ``failed`` with its message, never ``running``); a
surrogate joint name downloads as BVH; a loop file is built once however many ask for it, and streamed; a client
that never finishes its request head is cut off; one that leaves mid-body prints no traceback; ``1e400`` is
quoted as written; Ctrl-C and SIGTERM stop ``mocycle studio`` at once; ``mocycle report`` is safe for any title."""

from __future__ import annotations

import json
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import pytest

import mocycle
from mocycle.datasets import synthetic_walk
from mocycle.datasets.gltf_files import chain_document, gltf_file

pytest.importorskip("starlette")
httpx = pytest.importorskip("httpx")

from mocycle.studio import app as app_module  # noqa: E402
from mocycle.studio import server as server_module  # noqa: E402
from mocycle.studio.app import create_app  # noqa: E402
from studio_harness import api_client, served  # noqa: E402

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}


def analysed(client, timeout=120):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        data = client.get("/api/takes").json()
        if data["done"] == data["total"]:
            return {t["name"]: t for t in data["takes"]}
        time.sleep(0.05)
    raise AssertionError(f"the library was not analysed: {data}")


def wait(client, job_id, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        j = client.get(f"/api/jobs/{job_id}").json()
        if j["status"] not in ("queued", "running"):
            return j
        time.sleep(0.02)
    raise AssertionError(f"job {job_id} did not finish")


def renamed_glb(source, target, index: int, name: str):
    """The GLB ``source`` with node ``index`` renamed ``name`` (a lone surrogate is written as its JSON escape)."""
    data = source.read_bytes()
    n = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + n])
    doc["nodes"][index]["name"] = name
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + n:]
    body = struct.pack("<I4s", len(text), b"JSON") + text + rest
    target.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
    return target


@pytest.fixture(scope="module")
def lying(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lying")
    walk = synthetic_walk(n_frames=240).motion
    mocycle.write(walk, folder / "walk.bvh")
    renamed_glb(mocycle.write(walk, tmp_path_factory.mktemp("src") / "walk.glb"), folder / "odd.glb", 1, "\ud800")
    doc, blob = chain_document(3)
    gltf_file(folder / "piped.gltf", doc, blob, uri="piped.bin")
    (folder / "piped.bin").unlink()
    os.mkfifo(folder / "piped.bin")
    doc, blob = chain_document(3)
    doc["accessors"][1]["type"] = []
    gltf_file(folder / "typed.gltf", doc, blob)
    doc, blob = chain_document(3)
    doc["buffers"][0]["byteLength"] = 64
    gltf_file(folder / "secret.gltf", doc, blob, uri="../../../../../../etc/passwd")
    mocycle.write(walk[:120], folder / "buggy.bvh")
    return folder


@pytest.fixture(scope="module")
def client(lying):
    real = app_module.tasks.loop.run

    def loop(motion, options, *args, **kwargs):  # a bug in the analysis of one take
        if getattr(motion, "n_frames", 0) == 120:
            raise TypeError("a bug")
        return real(motion, options, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(app_module.tasks.loop, "run", loop)
        with api_client(create_app([lying])) as c:
            c.takes = analysed(c)
            yield c


def test_no_take_is_left_running_and_each_failure_says_why(client):
    takes = client.takes
    assert {t["status"] for t in takes.values()} <= {"done", "failed"}
    assert takes["walk.bvh"]["status"] == "done" and takes["odd.glb"]["status"] == "done"
    assert "a named pipe, not a regular file" in takes["piped.gltf"]["error"]
    assert "accessors[1].type must be text" in takes["typed.gltf"]["error"]
    assert "relative path to a file in the glTF's own folder" in takes["secret.gltf"]["error"]
    assert "root:" not in json.dumps(takes)
    assert takes["buggy.bvh"]["error"].startswith("internal error: TypeError")
    for name in ("piped.gltf", "typed.gltf", "secret.gltf"):
        t0 = time.monotonic()
        r = client.get(f"/api/takes/{takes[name]['id']}/motion")
        assert r.status_code == 400 and time.monotonic() - t0 < 5, r.text


def test_a_surrogate_joint_name_downloads_as_bvh(client):
    tid = client.takes["odd.glb"]["id"]
    job = client.post(f"/api/takes/{tid}/loop", json={"cycles": 2}).json()
    assert wait(client, job["id"])["status"] == "done"
    for suffix in ("bvh", "glb"):
        r = client.get(f"/api/jobs/{job['id']}/loop.{suffix}")
        assert r.status_code == 200, r.text
    text = client.get(f"/api/jobs/{job['id']}/loop.bvh").text
    assert "\ufffd" in text and mocycle.io.parse_bvh(text).n_joints == 22


def test_a_loop_file_is_built_once_for_many_downloads(lying, monkeypatch):
    built = []
    real = app_module.write_motion_file

    def counting(report, role, path):
        built.append(path.suffix)
        time.sleep(0.2)  # the others arrive while it is made
        return real(report, role, path)

    monkeypatch.setattr(app_module, "write_motion_file", counting)
    monkeypatch.setattr(app_module, "CHUNK", 4096)  # several pieces even for this small loop
    app = create_app([lying / "walk.bvh"])
    with api_client(app) as c:
        tid = analysed(c)["walk.bvh"]["id"]
        job = c.post(f"/api/takes/{tid}/loop", json={"cycles": 20}).json()["id"]
        assert wait(c, job)["status"] == "done"
        with served(app) as url:
            headers = {"X-Mocycle-Token": app.state.access.token}
            bodies = []

            def get():
                r = httpx.get(f"{url}api/jobs/{job}/loop.bvh", headers=headers, timeout=60)
                bodies.append((r.status_code, int(r.headers["content-length"]), r.content))

            threads = [threading.Thread(target=get) for _ in range(40)]
            for t in threads:
                t.start()
            for t in threads:
                t.join(60)
            files = [f.stat().st_size for f in app.state.studio.files.rglob("*.bvh")]
        assert built == [".bvh"]  # once, for forty
        assert len(bodies) == 40 and len({b for _, _, b in bodies}) == 1
        assert all(code == 200 and length == len(body) > 4096 for code, length, body in bodies)
        assert files == [len(bodies[0][2])]


def test_a_slow_request_head_is_cut_off_and_a_leaving_client_prints_nothing(lying, monkeypatch, capfd):
    monkeypatch.setattr(server_module.HeaderTimeout, "header_timeout_s", 1.0)
    app = create_app([lying / "walk.bvh"])
    with served(app) as url:
        port = int(url.rsplit(":", 1)[1].strip("/"))
        slow = []
        for _ in range(20):
            s = socket.create_connection(("127.0.0.1", port))
            s.sendall(b"GET /api/takes HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never the blank line
            slow.append(s)
        t0 = time.monotonic()
        for s in slow:
            s.settimeout(10)
            assert s.recv(100) == b""  # closed by the server
            s.close()
        assert time.monotonic() - t0 < 5
        # a client that sends half its body and leaves
        token = app.state.access.token
        for _ in range(3):
            s = socket.create_connection(("127.0.0.1", port))
            s.sendall(f"POST /api/takes/t0/loop HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                      f"Content-Type: application/json\r\nX-Mocycle-Token: {token}\r\nContent-Length: 1000\r\n\r\n"
                      f"{{\"cycles\"".encode())
            s.close()
        time.sleep(0.5)
        assert httpx.get(url + "api/takes", timeout=10).status_code == 200  # still serving
    err = capfd.readouterr().err
    assert "Traceback" not in err and "ClientDisconnect" not in err, err


def test_numbers_beyond_float_are_quoted_as_written(client):
    tid = client.takes["walk.bvh"]["id"]
    r = client.post(f"/api/takes/{tid}/loop", content=b'{"cycles": 1e400}',
                    headers={"Content-Type": "application/json"})
    assert r.status_code == 400 and "1e400" in r.json()["error"] and "Infinity" not in r.text, r.text
    r = client.post(f"/api/takes/{tid}/loop", content=b'{"cycles": -1e400}',
                    headers={"Content-Type": "application/json"})
    assert r.status_code == 400 and "-1e400" in r.json()["error"] and "Infinity" not in r.text, r.text


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_ctrl_c_and_sigterm_stop_the_studio_at_once(tmp_path, sig, code):
    """While the library's analysis loops a long take and a client holds a connection open, a signal ends the
    server within seconds, with one line and no traceback."""
    mocycle.write(synthetic_walk(n_frames=30_000, fps=120).motion, tmp_path / "long.bvh")
    proc = subprocess.Popen([sys.executable, "-m", "mocycle", "studio", str(tmp_path), "--no-browser", "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
    try:
        line = proc.stdout.readline()
        assert line.startswith("mocycle studio on http://127.0.0.1:"), line + proc.stderr.read()
        url = line.split()[3]
        port = int(url.rsplit(":", 1)[1].strip("/"))
        deadline = time.monotonic() + 60
        while httpx.get(url + "api/takes", timeout=30).json()["takes"][0]["status"] != "running":
            assert time.monotonic() < deadline
            time.sleep(0.05)
        held = socket.create_connection(("127.0.0.1", port))
        held.sendall(b"GET / HTTP/1.1\r\n")
        t0 = time.monotonic()
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=30)
        assert time.monotonic() - t0 < 8
        held.close()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == code, err
    assert "Traceback" not in err and err.strip().splitlines()[-1] in ("interrupted", "terminated"), err


def test_report_is_safe_for_any_title(tmp_path):
    from typer.testing import CliRunner

    from mocycle.cli import app

    name = 'walk<!--<script><\\script>&"\u2028.bvh'
    take = mocycle.write(synthetic_walk(n_frames=240).motion, tmp_path / name)
    out = tmp_path / "r.html"
    r = CliRunner().invoke(app, ["report", str(take), "-o", str(out)])
    assert r.exit_code == 0, r.output
    page = out.read_text()
    script = page.split('<script id="report-data" type="application/json">', 1)[1].split("</script>", 1)[0]
    assert "<" not in script and ">" not in script and "&" not in script
    data = json.loads(script)
    assert data["title"] == name
    assert page.count("<script") == 3  # the import map, the data, the module: no other opened by the title
