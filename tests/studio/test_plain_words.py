"""The studio says what it shows in plain words and draws the body, not the room (issue 37).

* A static root far from the body (the Bandai Namco files: ``joint_Root`` stays at the room's origin while
  ``Hips`` carries the walk) is not drawn as a bone to the hips: the payload's ``hidden`` names it, from the
  motion alone (the take here calls it ``anchor``), and the page draws neither it nor its bone.
* A figure that cannot be measured (the foot skate of a rig whose feet are not found by name) is ``null`` in the
  API and the report, "not measured" on the page, never ``NaN`` (which made ``/api/takes`` a 500).
* A refusal is a line of plain words (``error_line``, ``refusal_line``); each check's reason stays the detail.
"""

from __future__ import annotations

import json
import os
import time

import numpy as np
import pytest

from mocycle import write
from mocycle.datasets import synthetic_walk
from mocycle.motion import Motion, Skeleton

pytest.importorskip("starlette")
pytest.importorskip("httpx")

from mocycle.studio.app import create_app  # noqa: E402
from mocycle.studio.payload import detached_joints, unpack  # noqa: E402
from studio_harness import api_client  # noqa: E402

SIX = ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")


def anchored(motion: Motion, at=(0.0, 0.0, 0.0), moving: bool = False) -> Motion:
    """``motion`` under a new root joint ``anchor`` at ``at`` (static unless ``moving``: then it carries the hips'
    travel, as a root that moves with the body), the hips' translation taken relative to it: the body's world
    positions are the same."""
    s = motion.skeleton
    skel = Skeleton(("anchor", *s.names), [-1, *(np.asarray(s.parents) + 1)], np.vstack([at, s.offsets]),
                    [SIX, *s.channels], end_sites=[type(e)(e.parent + 1, e.offset, e.name) for e in s.end_sites])
    T = motion.n_frames
    rot = np.concatenate([np.tile([0.0, 0.0, 0.0, 1.0], (T, 1, 1)), motion.rotations], axis=1)
    trans = np.concatenate([np.tile(np.asarray(at, dtype=float), (T, 1, 1)), motion.translations], axis=1)
    trans[:, 1] -= np.asarray(at)
    if moving:  # the anchor follows the hips along the floor: a root that moves with the body
        floor = trans[:, 1].copy()
        floor[:, 1] = 0.0
        trans[:, 0] += floor
        trans[:, 1] -= floor
    return Motion(skel, rot, trans, motion.frame_time)


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=240, fps=30).motion


def test_a_static_root_far_from_the_body_is_hidden_and_nothing_else(walk):
    room = anchored(walk)
    np.testing.assert_allclose(room.world_positions()[:, 1:], walk.world_positions(), atol=1e-9)
    assert room.travel_joint == 1 and np.ptp(room.world_positions()[:, 0], axis=0).max() == 0
    assert detached_joints(room) == [0]
    assert detached_joints(walk) == []  # the hips carry the travel themselves: nothing above the body
    assert detached_joints(anchored(walk, moving=True)) == []  # a root that moves with the body is drawn
    # a static root right at the hips' height, never farther from them than a bone of the body: drawn
    hips = walk.world_positions()[:, 0]
    near = anchored(walk[:4], at=tuple(hips[:4].mean(axis=0)))
    assert np.linalg.norm(near.world_positions()[:, 0] - near.world_positions()[:, 1], axis=1).max() < \
        walk.skeleton.bone_lengths().max()
    assert detached_joints(near) == []
    # one frame (nothing moves, the body's root is the travel joint): the anchor is still above it and away
    assert detached_joints(room[:1]) == [0]


def test_the_payload_and_the_loops_hide_it(walk, tmp_path):
    write(anchored(walk), tmp_path / "room.bvh")
    write(walk, tmp_path / "walk.bvh")
    with api_client(create_app([tmp_path])) as client:
        takes = {t["name"]: t["id"] for t in client.get("/api/takes").json()["takes"]}
        header, arrays = unpack(client.get(f"/api/takes/{takes['room.bvh']}/motion").content)
        assert header["names"][0] == "anchor" and header["hidden"] == [0] and header["travel"] == 1
        assert np.linalg.norm(arrays["positions"][:, 0] - arrays["positions"][:, 1], axis=1).max() > 1.5 * \
            header["height"]  # drawn, it would be a bone longer than the body across the room
        assert unpack(client.get(f"/api/takes/{takes['walk.bvh']}/motion").content)[0]["hidden"] == []
        job = client.post(f"/api/takes/{takes['room.bvh']}/loop", json={"root": "motion"}).json()
        j = wait(client, job)
        assert j["status"] == "done", j
        loop, _ = unpack(client.get(f"/api/jobs/{j['id']}/motion").content)
        assert loop["hidden"] == [0]


def wait(client, job, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        j = client.get(f"/api/jobs/{job['id']}").json()
        if j["status"] not in ("queued", "running"):
            return j
        time.sleep(0.05)
    raise AssertionError(f"job {job} did not finish")


def feetless(motion: Motion) -> Motion:
    """``motion`` with joints named ``b0``, ``b1``, ...: its feet are not found by name."""
    s = motion.skeleton
    skel = Skeleton(tuple(f"b{j}" for j in range(s.n_joints)), s.parents, s.offsets, s.channels,
                    end_sites=s.end_sites)
    return Motion(skel, motion.rotations, motion.translations, motion.frame_time)


def test_a_figure_not_measured_is_null_not_nan(walk, tmp_path):
    write(feetless(walk), tmp_path / "rig.bvh")
    with api_client(create_app([tmp_path])) as client:
        t0 = time.monotonic()
        while (r := client.get("/api/takes")).status_code == 200 and r.json()["done"] < 1:
            assert time.monotonic() - t0 < 120
            time.sleep(0.1)
        assert r.status_code == 200 and "NaN" not in r.text and "null_because_not_finite" in r.text, r.text
        (take,) = r.json()["takes"]
        assert take["status"] == "done" and take["loops"][0]["skate"] is None
        j = wait(client, client.post(f"/api/takes/{take['id']}/loop", json={}).json())
        r = client.get(f"/api/jobs/{j['id']}")
        assert r.status_code == 200 and "NaN" not in r.text and r.json()["result"]["loop"]["skate"] is None


def test_the_report_of_such_a_rig_is_strict_json(walk, tmp_path):
    from mocycle import tasks
    from mocycle.studio.report import build_report

    rig = feetless(walk)
    page = build_report("rig", rig, tasks.loop.run(rig))
    data = page.split('<script id="report-data" type="application/json">', 1)[1].split("</script>", 1)[0]
    def refuse(constant):
        raise AssertionError(f"{constant} in the report's JSON")

    assert json.loads(data, parse_constant=refuse)["summary"]["skate"] is None


def test_a_refusal_is_a_line_of_plain_words():
    from mocycle.cycle.checks import FailedCheck
    from mocycle.errors import LoopRefused
    from mocycle.studio.jobs import Jobs
    from mocycle.studio.library import Take, loop_summary

    failed = [FailedCheck("seam", 4.2, 3.0, "the seam jumps: the step across the wrap is 4.2 times the steps next "
                                            "to it (limit 3)")]
    jobs = Jobs(workers=1)

    def refuse(job):
        raise LoopRefused("walk.bvh: not a loop (seam: the seam jumps ...); --force writes it anyway", failed)

    job = jobs.submit("loop", refuse)
    t0 = time.monotonic()
    while job.status in ("queued", "running"):
        assert time.monotonic() - t0 < 10
        time.sleep(0.01)
    d = job.to_dict()
    assert d["status"] == "refused" and d["error"].startswith("walk.bvh: not a loop (seam:")
    assert d["error_line"] == "not a loop: the loop jumps where it wraps" and "--force" not in d["error_line"]
    jobs.shutdown()
    summary = loop_summary({"part": 0, "period_frames": 30.0, "fps": 30.0, "cycle_frames": 30,
                            "failed_checks": [f.to_dict() for f in failed]})
    assert summary["refusal_line"] == "not a loop: the loop jumps where it wraps" and "4.2 times" in summary["refusal"]
    take = Take(id="t0", path=__import__("pathlib").Path("x.bvh"), reason="; ".join(["part 0 (walk straight, frames "
                "0-50) does not loop: only 1.4 strides, too short for a loop (at least 2 are needed)"] * 4))
    d = take.to_dict()
    assert len(d["reason_line"]) <= 160 and d["reason_line"].endswith(" …") and len(d["reason"]) > 300


@pytest.mark.browser
def test_the_page_draws_no_bone_from_the_room(walk, tmp_path):
    """In the browser: the figure of the anchored take has no joint or bone for the anchor, and the one of the
    plain walk draws every joint."""
    pytest.importorskip("uvicorn")
    pytest.importorskip("playwright")
    from studio_harness import CHROMIUM, chromium, served, watch_console

    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is absent (make chromium installs Debian's chromium)")
    write(anchored(walk), tmp_path / "room.bvh")
    with served(create_app([tmp_path])) as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1200, "height": 800}, bypass_csp=True)
        errors = watch_console(page)
        page.goto(url)
        page.wait_for_function("window.__studio && window.__studio.ready && window.__studio.viewer.figures.main",
                               timeout=60_000)
        fig = page.evaluate("(() => { const f = window.__studio.viewer.figures.main; return {points: f.points, "
                            "bones: f.bones, joints: f.jointMesh.count, parents: f.parents}; })()")
        P = len(fig["parents"])
        assert 0 not in fig["points"] and fig["joints"] == P - 1
        assert all(0 not in bone for bone in fig["bones"]) and len(fig["bones"]) == P - 2  # all but anchor-hips
        assert not errors, errors
