"""The studio in a real browser (Debian's chromium, headless, SwiftShader WebGL, driven by Playwright):
the page loads cleanly, the library lists the takes, playing and scrubbing move the skeleton, a stroke drawn
on the plane becomes an animation whose poses follow the stroke, markers re-lay-out and go, export works,
``mocycle report`` opens offline."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.browser  # make check leaves these out

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
pytest.importorskip("playwright")

from mocycle import read  # noqa: E402
from mocycle.io.bvh import parse_bvh  # noqa: E402
from mocycle.keyframes import BackProjection, joint_weights, pose_distance_matrix  # noqa: E402
from mocycle.studio.app import create_app  # noqa: E402
from studio_harness import CHROMIUM, chromium, served, watch_console  # noqa: E402

if not os.path.exists(CHROMIUM):
    pytest.skip(f"{CHROMIUM} is absent (make chromium installs Debian's chromium)", allow_module_level=True)

READY = "window.__studio && window.__studio.ready"


@pytest.fixture(scope="module")
def session(library):
    with served(create_app([library])) as url, chromium() as browser:
        # bypass_csp: Playwright polls wait_for_function with eval, which the page's CSP forbids (tests/studio/
        # test_security.py drives the page under its CSP)
        page = browser.new_page(viewport={"width": 1400, "height": 900}, accept_downloads=True, bypass_csp=True)
        errors = watch_console(page)
        page.goto(url)
        page.wait_for_function(READY, timeout=60_000)
        yield page, errors, browser


def open_take(page, name):
    page.locator('[data-testid="take"]', has_text=name).click()
    page.wait_for_function(f"document.getElementById('take-name').textContent === {name!r}")
    page.wait_for_function("window.__studio.keys && window.__studio.plane && "
                           "document.getElementById('plane-status').textContent.includes('keyframes')", timeout=60_000)


def main_pose(page):
    return np.array(page.evaluate("window.__studio.mainPose()"))


def test_library_lists_the_takes_and_their_loops(session):
    page, errors, _ = session
    takes = page.locator('[data-testid="take"]')
    assert takes.count() == 2
    page.wait_for_function("window.__studio.library && window.__studio.library.done === 2", timeout=120_000)
    page.wait_for_timeout(700)  # the next poll draws the analysed rows
    walk = takes.filter(has_text="walk.bvh").inner_text()
    assert "240 frames" in walk and "1 loop" in walk and "period 1.0" in walk and "seam" in walk
    assert "no loop" in takes.filter(has_text="wander.bvh").inner_text()
    assert page.locator('[data-testid="viewer"] canvas').count() == 1
    assert not errors, errors


def test_playing_and_scrubbing_change_the_pose(session):
    page, errors, _ = session
    open_take(page, "walk.bvh")
    page.evaluate("window.__studio.player.pause(); window.__studio.player.setFrame(0)")  # the thumb at the left
    n = page.evaluate("window.__studio.stats.scrub.length")
    box = page.locator("#scrub").bounding_box()
    page.mouse.click(box["x"] + 0.2 * box["width"], box["y"] + box["height"] / 2)
    a = main_pose(page)
    page.mouse.click(box["x"] + 0.6 * box["width"], box["y"] + box["height"] / 2)
    b = main_pose(page)
    assert np.abs(a - b).max() > 1.0
    page.locator("#play").click()
    page.wait_for_timeout(400)
    c = main_pose(page)
    assert np.abs(c - b).max() > 1.0
    assert page.evaluate("window.__studio.stats.scrub.length") >= n + 2
    page.wait_for_function("document.getElementById('loop-status').textContent.startsWith('loop ')", timeout=120_000)
    assert page.evaluate("!!window.__studio.viewer.figures.loop")
    assert not errors, errors


def test_the_page_back_projects_as_the_library_does(session, library):
    page, errors, _ = session
    open_take(page, "walk.bvh")
    take = read(library / "walk.bvh")
    key = np.array(page.evaluate("window.__studio.keys"))
    markers = np.array(page.evaluate("window.__studio.markers"), dtype=np.float32).astype(float)
    rng = np.random.default_rng(0)
    pts = markers[rng.integers(0, len(key), 3)] + rng.normal(scale=0.1 * np.ptp(markers), size=(3, 2))
    q, _ = BackProjection(markers, take.rotations[key])(pts)
    expected = take.replace(rotations=q, translations=np.broadcast_to(take.translations[0], (3, *take.translations
                                                                                                 .shape[1:])))
    expected = expected.world_positions(end_sites=True)
    for p, e in zip(pts, expected, strict=True):
        got = np.array(page.evaluate("([x, y]) => Array.from(window.__studio.pose.pose(x, y))", p.tolist()))
        assert np.abs(got.reshape(-1, 3) - e).max() < 1e-3 * 170  # float32 keyframes, same map


def test_a_stroke_becomes_an_animation_that_follows_it(session, library, tmp_path):
    page, errors, _ = session
    open_take(page, "wander.bvh")
    half = 120
    path = np.array(page.evaluate(f"[...Array({half}).keys()].filter((i) => i % 3 === 0)"
                                   ".map((i) => window.__studio.framePixel(i))"))
    marks = np.array(page.evaluate("window.__studio.markers.map((_, k) => window.__studio.markerPixel(k))"))
    # a press on a marker drags it: the stroke starts at the first point clear of every marker
    clear = np.linalg.norm(path[:, None] - marks[None], axis=2).min(axis=1) > 12
    path = path[int(np.argmax(clear)):].tolist()
    page.mouse.move(*path[0])
    page.mouse.down()
    for x, y in path[1:]:
        page.mouse.move(x, y)
        page.wait_for_timeout(25)
    page.mouse.up()
    page.wait_for_function("document.querySelector('[data-testid=export]').hasAttribute('href')", timeout=60_000)
    assert page.evaluate("window.__studio.stats.draw.length") >= len(path) - 1
    with page.expect_download() as info:
        page.locator('[data-testid="export"]').click()
    target = tmp_path / "authored.bvh"
    info.value.save_as(target)
    authored = parse_bvh(target.read_text())
    take = read(library / "wander.bvh")
    assert authored.skeleton.same_as(take.skeleton) and authored.n_frames >= 20
    near = pose_distance_matrix(authored.rotations, joint_weights(take.skeleton), take.rotations).argmin(axis=1)
    assert np.mean(near < half + 15) > 0.85, near  # poses of the stroked first half ...
    assert np.corrcoef(near, np.arange(len(near)))[0, 1] > 0.8, near  # ... in the stroke's order
    assert page.evaluate("window.__studio.player.kind") == "authored"
    assert not errors, errors


def test_dragging_a_marker_relays_out_and_clicking_removes_it(session):
    page, errors, _ = session
    open_take(page, "walk.bvh")
    before = np.array(page.evaluate("Array.from(window.__studio.planeView.points)"))
    n = page.evaluate("window.__studio.relayouts || 0")
    k = len(page.evaluate("window.__studio.keys")) // 2
    x, y = page.evaluate(f"window.__studio.markerPixel({k})")
    page.mouse.move(x, y)
    page.mouse.down()
    for i in range(1, 11):
        page.mouse.move(x + 4 * i, y - 3 * i)
    page.mouse.up()
    page.wait_for_function(f"(window.__studio.relayouts || 0) > {n}", timeout=60_000)
    after = np.array(page.evaluate("Array.from(window.__studio.planeView.points)"))
    assert np.abs(after - before).max() > 1e-3
    keys = page.evaluate("window.__studio.keys")
    x2, y2 = page.evaluate(f"window.__studio.markerPixel({k})")
    assert abs(x2 - (x + 40)) < 2 and abs(y2 - (y - 30)) < 2
    page.mouse.click(x2, y2)
    page.wait_for_function(f"window.__studio.keys.length === {len(keys) - 1}")
    page.wait_for_function(f"(window.__studio.relayouts || 0) > {n + 1}", timeout=60_000)
    assert not errors, errors


def test_report_is_one_file_that_opens_offline(session, library, tmp_path):
    out = tmp_path / "report.html"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    r = subprocess.run([sys.executable, "-m", "mocycle", "report", str(library / "walk.bvh"), "-o", str(out)],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "http://" not in text.replace("http://www.w3.org", "") and "<script src" not in text
    browser = session[2]
    page = browser.new_page(viewport={"width": 1200, "height": 800})
    try:
        errors = watch_console(page)
        page.route("**/*", lambda route: route.abort() if not route.request.url.startswith(("file:", "data:"))
                   else route.continue_())
        page.goto(out.as_uri())
        page.wait_for_function(READY, timeout=60_000)
        assert "period" in page.locator('[data-testid="metrics"]').inner_text()
        assert page.evaluate("!!window.__studio.viewer.figures.loop")
        page.locator("#play").click()
        box = page.locator("#scrub").bounding_box()
        page.mouse.click(box["x"] + 0.1 * box["width"], box["y"] + box["height"] / 2)
        a = np.array(page.evaluate("Array.from(window.__studio.viewer.figures.main.last)"))
        page.mouse.click(box["x"] + 0.7 * box["width"], box["y"] + box["height"] / 2)
        b = np.array(page.evaluate("Array.from(window.__studio.viewer.figures.main.last)"))
        assert np.abs(a - b).max() > 1.0
        assert not errors, errors
    finally:
        page.close()
