"""The studio's page under its own Content-Security-Policy in Debian's chromium (no ``bypass_csp``): it loads
with no violation, its own requests carry the token and work, names from files stay text, a take that cannot
be read leaves nothing of the previous take, and a page of another site cannot start work."""

from __future__ import annotations

import json
import os
import time

import pytest

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")
pytest.importorskip("playwright")

from mocycle.studio.app import create_app  # noqa: E402
from studio_harness import CHROMIUM, chromium, served, watch_console  # noqa: E402

if not os.path.exists(CHROMIUM):
    pytest.skip(f"{CHROMIUM} is absent (make chromium installs Debian's chromium)", allow_module_level=True)

XSS = '<img src=x onerror="window.__pwned=1">.bvh'


def until(page, expression: str, timeout: float = 120.0):
    """Poll ``expression`` with page.evaluate (wait_for_function would eval a string, which the CSP forbids)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        value = page.evaluate(expression)
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"never true: {expression}")


def click_take(page, name):
    page.evaluate(f"[...document.querySelectorAll('[data-testid=take]')].find((r) => "
                  f"r.querySelector('.name').textContent === {json.dumps(name)}).click()")


@pytest.mark.browser
def test_the_page_under_its_csp(hostile, tmp_path):
    app = create_app([hostile])
    studio = app.state.studio
    with served(app) as url, chromium() as browser:
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        errors = watch_console(page)
        page.goto(url)
        until(page, "window.__studio && window.__studio.ready")
        until(page, "window.__studio.library && window.__studio.library.done === window.__studio.library.total")
        time.sleep(4.5)  # the next poll draws the analysed rows
        # names from files are text: the HTML-looking name is shown as it is, no element made of it
        names = page.evaluate("[...document.querySelectorAll('#takes .name')].map((e) => e.textContent)")
        assert XSS in names and "bad\\xffname.bvh" in names
        assert page.evaluate("document.querySelectorAll('#takes img').length") == 0
        assert page.evaluate("window.__pwned === undefined")
        passwd = page.evaluate("[...document.querySelectorAll('[data-testid=take]')].find((r) => "
                               "r.querySelector('.name').textContent === 'passwd.bvh').textContent")
        assert "outside the served folder" in passwd and "root:" not in passwd
        # the page's own POST (a loop job) works under the CSP with the token and JSON
        click_take(page, "walk.bvh")
        until(page, "document.getElementById('take-name').textContent === 'walk.bvh' && "
                    "document.getElementById('loop-status').dataset.state === 'ok'")
        # a take that cannot be read: no exception, its own name, nothing of the walk left to play
        for name, words in (("notbvh.bvh", "cannot read this take"), ("passwd.bvh", "outside the served folder")):
            click_take(page, name)
            # the status of the take before may still show for a moment (both failed): wait for this one's words
            until(page, f"document.getElementById('take-name').textContent === {json.dumps(name)} && "
                        "document.getElementById('loop-status').dataset.state === 'failed' && "
                        f"document.getElementById('loop-status').textContent.includes({json.dumps(words)})")
            assert words in page.locator('[data-testid="loop-status"]').inner_text()
            assert page.evaluate("window.__studio.player.main === null && !window.__studio.viewer.figures.main")
            assert page.locator('[data-testid="loop-bvh"]').get_attribute("href") is None
        click_take(page, "walk.bvh")  # and back: it plays again
        until(page, "document.getElementById('take-name').textContent === 'walk.bvh' && "
                    "window.__studio.player.main !== null && "
                    "document.getElementById('loop-status').dataset.state === 'ok'")
        page.screenshot(path=str(tmp_path / "csp.png"))
        # no CSP violation, no uncaught exception: only chromium's note of the two takes' 400 answers
        assert errors == ["console.error: Failed to load resource: the server responded with a status of 400 "
                          "(Bad Request)"] * 2, errors

        # a page of another site: its requests start nothing
        held = studio.interactive.held()
        attacker = browser.new_page()
        attacker.route("http://attacker.example/", lambda route: route.fulfill(
            status=200, content_type="text/html", body="<html><body>hello</body></html>"))
        attacker.goto("http://attacker.example/")
        attacker.evaluate("""async (url) => {
            for (const kind of ["text/plain", "application/json"]) {
              try { await fetch(url, {method: "POST", mode: "no-cors", headers: {"Content-Type": kind},
                                       body: '{"cycles": 20}'}); } catch (e) {}
            }
            const f = document.createElement("form");
            f.method = "POST"; f.action = url; f.enctype = "text/plain";
            const i = document.createElement("input"); i.name = '{"cycles": 20, "x": "'; i.value = '"}';
            f.appendChild(i); document.body.appendChild(f); f.submit();
        }""", f"{url}api/takes/t4/loop")
        time.sleep(2)
        assert studio.interactive.held() == held
