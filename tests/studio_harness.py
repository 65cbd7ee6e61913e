"""Drive the studio in Debian's chromium through Playwright, the studio served on a free port in a thread: what the
tests, the screenshots and the latency benchmark (``benchmarks/studio.py``) share (Playwright and uvicorn are
imported when used).  A test helper, so not in the installed package: ``from studio_harness import ...``
(``tests`` is on pytest's path, as for ``helpers`` and ``fuzzing``)."""

from __future__ import annotations

import contextlib
import os
import socket
import threading
import time


def _import_test_client():
    """Starlette's TestClient, imported now, in the main thread, before any studio exists: its import warns
    (starlette 1.x prefers httpx2), and a studio's analysis thread reading a BVH sets the process's warning
    filters to "error" for a moment (``warnings.catch_warnings`` is not thread-safe), which made that warning
    an exception when the first ``api_client`` raced it."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            from starlette.testclient import TestClient
        except ImportError:  # the tests that need it skip without starlette or httpx
            return None
    return TestClient


_TestClient = _import_test_client()

CHROMIUM = os.environ.get("MOCYCLE_CHROMIUM", "/usr/bin/chromium")
ARGS = ["--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
        "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run"]


@contextlib.contextmanager
def served(app):
    """``app`` on 127.0.0.1 at a free port, in a thread; yields the page's URL."""
    import uvicorn

    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    from mocycle.studio.server import config

    server = uvicorn.Server(config(app, log_level="warning", lifespan="on"))  # as mocycle studio serves it
    access = getattr(getattr(app, "state", None), "access", None)
    if access is not None:
        access.bind("127.0.0.1", sock.getsockname()[1])  # as mocycle studio does: only this Host is answered
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    t0 = time.monotonic()
    while not server.started and time.monotonic() - t0 < 30:
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{sock.getsockname()[1]}/"
    finally:
        server.should_exit = True
        thread.join(15)
        sock.close()


def api_client(app, **kwargs):
    """Starlette's TestClient for the studio app as its own page talks to it: ``Host: 127.0.0.1`` and the
    server's token on every request (``headers=`` adds or replaces headers)."""
    headers = {"X-Mocycle-Token": app.state.access.token, **kwargs.pop("headers", {})}
    return _TestClient(app, base_url=kwargs.pop("base_url", "http://127.0.0.1"), headers=headers, **kwargs)


@contextlib.contextmanager
def chromium():
    """A headless chromium (SwiftShader WebGL) through Playwright; never downloads a browser."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=ARGS)
        try:
            yield browser
        finally:
            browser.close()


def watch_console(page) -> list[str]:
    """Collects the page's console errors and uncaught exceptions."""
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"pageerror: {e}"))
    return errors
