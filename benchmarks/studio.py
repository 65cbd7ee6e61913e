"""The studio's speed in a real browser, and the screenshots of docs/studio.md.

    python benchmarks/studio.py [--shots docs/studio] [--real]

Serves the studio on generated takes (a 1000-frame walk, a 240-frame wandering take, a 500-frame walk read
with the phase of a slower walk so that its loop is refused, as in tests/studio/test_studio_refusal.py; with
``--real`` also a CMU/iClone take of ../shared/data, 100 joints) and drives Debian's chromium (headless,
SwiftShader WebGL, no GPU) through Playwright.  Measured in the page with ``performance.now()``:

* time to first render: click on the take in the library -> its motion fetched, decoded and drawn;
* pose update while scrubbing: the slider's input event -> pose set and ``renderer.render`` returned;
* pose update while hovering and drawing on the plane: the pointer event -> back-projection (RBF, nearest
  rotations, forward kinematics in JS) -> pose set and rendered;
* the next animation frame after an update (what the screen can show at the earliest);

and on the server: the time per stroke (``tasks.author``: back-projection, root placement, foot locking) and
the page's round trip (POST + fetching the authored motion).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
sys.path.insert(1, str(REPO / "tests"))  # the browser harness the studio tests use: tests/studio_harness.py

import mocycle.cycle.extract as extract_module  # noqa: E402
from mocycle import write  # noqa: E402
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk  # noqa: E402
from mocycle.phase import find_phase  # noqa: E402
from mocycle.studio.app import create_app  # noqa: E402
from studio_harness import chromium, served, watch_console  # noqa: E402

READY = "window.__studio && window.__studio.ready"


def stats(values) -> str:
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return "–"
    return f"median {np.median(v):6.2f} ms  p95 {np.percentile(v, 95):6.2f} ms  max {v.max():6.2f} ms  (n={v.size})"


def open_take(page, name):
    page.locator('[data-testid="take"]', has_text=name).click()
    page.wait_for_function(f"document.getElementById('take-name').textContent === {name!r}")
    page.wait_for_function("window.__studio.plane && document.getElementById('plane-status').textContent"
                           ".includes('keyframes')", timeout=120_000)


def next_frame_latency(page, n=30):
    """Event -> pose rendered -> the next requestAnimationFrame, for scrub updates driven from the page."""
    return page.evaluate(f"""async () => {{
      const S = window.__studio, out = [], T = S.player.main.header.frames;
      for (let i = 0; i < {n}; i++) {{
        const t0 = performance.now();
        S.player.setFrame((i * 37) % T);
        await new Promise((r) => requestAnimationFrame(r));
        out.push(performance.now() - t0);
      }}
      return out; }}""")


def finished_latency(page, n=30):
    """Scrub updates driven from the page, timed until the GPU (SwiftShader: the CPU) finished drawing."""
    return page.evaluate(f"""() => {{
      const S = window.__studio, out = [], T = S.player.main.header.frames, gl = S.viewer.renderer.getContext();
      for (let i = 0; i < {n}; i++) {{
        const t0 = performance.now();
        S.player.setFrame((i * 37) % T);
        gl.finish();
        out.push(performance.now() - t0);
      }}
      return out; }}""")


def idle_frame_interval(page, n=30):
    """Intervals between animation frames with nothing to draw (the page's own frame cadence)."""
    return page.evaluate(f"""async () => {{
      const out = []; let last = await new Promise((r) => requestAnimationFrame(r));
      for (let i = 0; i < {n}; i++) {{
        const now = await new Promise((r) => requestAnimationFrame(r));
        out.push(now - last); last = now;
      }}
      return out; }}""")


def stroke(page, frames, pause_ms=20):
    path = np.array(page.evaluate("(frames) => frames.map((i) => window.__studio.framePixel(i))", list(frames)))
    marks = np.array(page.evaluate("window.__studio.markers.map((_, k) => window.__studio.markerPixel(k))"))
    clear = np.linalg.norm(path[:, None] - marks[None], axis=2).min(axis=1) > 12
    path = path[int(np.argmax(clear)):]
    n = page.evaluate("window.__studio.stats.strokes.length")
    page.mouse.move(*path[0])
    page.mouse.down()
    for x, y in path[1:]:
        page.mouse.move(x, y)
        page.wait_for_timeout(pause_ms)
    page.mouse.up()
    page.wait_for_function(f"window.__studio.stats.strokes.length > {n}", timeout=60_000)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--shots", type=Path, help="write the screenshots of docs/studio.md into this folder")
    ap.add_argument("--real", action="store_true", help="also a CMU/iClone take (../shared/data)")
    args = ap.parse_args()
    if args.shots:
        args.shots = args.shots.resolve()
    folder = Path(tempfile.mkdtemp(prefix="mocycle-studio-"))
    write(synthetic_walk(n_frames=1000).motion, folder / "walk_1000.bvh")
    write(synthetic_nonperiodic(n_frames=240).motion, folder / "wander_240.bvh")
    # a take whose loop is refused (fit check): a walk given the phase of a walk 1.5 times slower, the period
    # found wrong as on CMU's basketball take (the shared walks all pass their checks)
    write(synthetic_walk(n_frames=500, noise_deg=1.0, seed=1).motion, folder / "limp_500.bvh")
    wrong = find_phase(synthetic_walk(n_frames=500, period_s=1.5, noise_deg=1.0, seed=4).motion)
    real_phase = extract_module.find_phase
    extract_module.find_phase = lambda m, *a, **k: wrong if m.n_frames == 500 else real_phase(m, *a, **k)
    paths = [folder]
    real = REPO.parent / "shared" / "data" / "cmu-iclone" / "07_01.bvh"
    if args.real and real.exists():
        paths.append(real)
    t0 = time.perf_counter()
    with served(create_app(paths)) as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1440, "height": 900}, accept_downloads=True,
                                bypass_csp=True)  # wait_for_function evaluates strings
        errors = watch_console(page)
        page.goto(url)
        page.wait_for_function(READY, timeout=120_000)
        page.wait_for_function("window.__studio.library.done === window.__studio.library.total", timeout=300_000)
        page.wait_for_timeout(600)
        print(f"library of {len(page.locator('[data-testid=take]').all())} takes analysed in "
              f"{time.perf_counter() - t0:.1f} s (page open, background jobs)")
        if args.shots:
            args.shots.mkdir(parents=True, exist_ok=True)
        # -- time to first render of the 1000-frame take (the other take first, so each click loads it anew)
        for _ in range(5):
            open_take(page, "wander_240.bvh")
            open_take(page, "walk_1000.bvh")
        first = [r["ms"] for r in page.evaluate("window.__studio.stats.firstRender_ms") if r["frames"] == 1000]
        print(f"time to first render, 1000-frame take (22 joints + 5 End Sites): {stats(first)}")
        page.wait_for_function("document.getElementById('loop-status').textContent.startsWith('loop ')",
                               timeout=120_000)
        if args.shots:
            page.locator("#play").click() if page.locator("#play").inner_text() != "▶" else None
            page.wait_for_timeout(300)
            page.screenshot(path=str(args.shots / "review.png"))
        # -- scrubbing with the mouse on the slider
        page.evaluate("window.__studio.stats.scrub.length = 0")
        page.locator("#play").click() if page.locator("#play").inner_text() != "▶" else None
        box = page.locator("#scrub").bounding_box()
        y = box["y"] + box["height"] / 2
        page.mouse.move(box["x"] + 5, y)
        page.mouse.down()
        for i in range(60):
            page.mouse.move(box["x"] + 5 + (box["width"] - 10) * i / 59, y)
        page.mouse.up()
        print(f"pose update while scrubbing (event -> rendered): {stats(page.evaluate('window.__studio.stats.scrub'))}")
        print(f"scrub update -> drawn (gl.finish):               {stats(finished_latency(page))}")
        print(f"scrub update -> next animation frame:            {stats(next_frame_latency(page))}")
        print(f"animation frame interval, nothing redrawn:       {stats(idle_frame_interval(page))}")
        # -- hovering and drawing on the plane
        plane = page.locator('[data-testid="plane"]').bounding_box()
        page.evaluate("window.__studio.stats.hover.length = 0; window.__studio.stats.draw.length = 0")
        for i in range(60):
            page.mouse.move(plane["x"] + plane["width"] * (0.2 + 0.6 * i / 59), plane["y"] + plane["height"] * 0.5)
        print(f"pose update while hovering the plane:            {stats(page.evaluate('window.__studio.stats.hover'))}")
        for _ in range(5):
            stroke(page, range(0, 500, 5))
        print(f"pose update while drawing a stroke:              {stats(page.evaluate('window.__studio.stats.draw'))}")
        s = page.evaluate("window.__studio.stats.strokes")
        print(f"server time per stroke ({s[-1]['frames']}-{max(r['frames'] for r in s)} frames authored): "
              f"{stats([r['server_ms'] for r in s])}")
        print(f"page round trip per stroke (POST + authored motion):      {stats([r['round_trip_ms'] for r in s])}")
        if args.shots:
            page.wait_for_timeout(800)
            page.screenshot(path=str(args.shots / "authoring.png"))
            page.locator('[data-testid="plane"]').screenshot(path=str(args.shots / "plane.png"))
            open_take(page, "wander_240.bvh")
            stroke(page, range(0, 120, 3), pause_ms=25)
            page.wait_for_timeout(800)
            page.locator('[data-testid="plane"]').screenshot(path=str(args.shots / "plane-wander.png"))
            page.select_option("#layout", "overlay")
            open_take(page, "walk_1000.bvh")
            page.wait_for_function("document.getElementById('loop-status').textContent.startsWith('loop ')",
                                   timeout=120_000)
            page.wait_for_timeout(500)
            for frame in (130, 610):  # paused: the loop in step with the take, early and after 8 cycles
                page.evaluate(f"window.__studio.player.pause(); window.__studio.player.setFrame({frame})")
                page.wait_for_timeout(300)
                page.locator("#review").screenshot(path=str(args.shots / f"overlay-{frame}.png"))
            page.select_option("#layout", "side")
            # -- the refused take: refused in the library and the review; force shows it marked
            open_take(page, "limp_500.bvh")
            page.wait_for_function("document.getElementById('loop-status').dataset.state === 'refused'",
                                   timeout=120_000)
            page.wait_for_timeout(300)
            page.screenshot(path=str(args.shots / "refused.png"))
            page.locator('[data-testid="force-loop"]').click()
            page.wait_for_function("document.getElementById('loop-status').dataset.state === 'forced'",
                                   timeout=120_000)
            page.evaluate("window.__studio.player.pause(); window.__studio.player.setFrame(200)")
            page.wait_for_timeout(300)
            page.locator("#review").screenshot(path=str(args.shots / "forced.png"))
            page.locator('[data-testid="force"]').uncheck()
            page.locator("#grid-toggle").click()
            page.locator("#library").screenshot(path=str(args.shots / "library-grid.png"))
            page.locator("#grid-toggle").click()
            page.locator("#library").screenshot(path=str(args.shots / "library.png"))
        if args.real and real.exists():
            t = time.perf_counter()
            open_take(page, real.name)
            print(f"{real.name} (100 joints): opened with its plane in {time.perf_counter() - t:.1f} s; first render "
                  f"{page.evaluate('window.__studio.stats.firstRender_ms').pop()['ms']:.0f} ms")
            if args.shots:
                page.wait_for_function("document.getElementById('loop-status').textContent.startsWith('loop ')",
                                       timeout=120_000)
                page.wait_for_timeout(1500)
                page.screenshot(path=str(args.shots / "iclone.png"))
                page.select_option("#layout", "overlay")
                page.evaluate("window.__studio.player.pause(); window.__studio.player.setFrame(100)")
                page.wait_for_timeout(300)
                page.locator('[data-testid="viewer"]').screenshot(path=str(args.shots / "overlay-iclone.png"))
                page.select_option("#layout", "side")
            page.evaluate("window.__studio.stats.hover.length = 0")
            for i in range(40):
                page.mouse.move(plane["x"] + plane["width"] * (0.2 + 0.6 * i / 39), plane["y"] + plane["height"] * 0.4)
            print(f"  pose update while hovering the plane: {stats(page.evaluate('window.__studio.stats.hover'))}")
        print("console errors:", errors or "none")
    if args.shots:
        import subprocess

        report = args.shots / "report.html"
        subprocess.run([sys.executable, "-m", "mocycle", "report", str(folder / "walk_1000.bvh"), "-o", str(report)],
                       check=True, env={"PYTHONPATH": str(REPO / "src"), "PATH": "/usr/bin:/bin"})
        with chromium() as browser:
            page = browser.new_page(viewport={"width": 1300, "height": 760})
            page.goto(report.as_uri())
            page.wait_for_function(READY, timeout=60_000)
            page.wait_for_timeout(1200)
            page.screenshot(path=str(args.shots / "report.png"))
        print(f"report: {report.stat().st_size / 1e6:.2f} MB for a 1000-frame take")
        report.unlink()
    print(f"total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
