"""``mocycle report``: one self-contained HTML file (viewer, loop, phase strip, metrics), no server needed.

Everything is inline: three.js and the page's modules as ``data:`` URLs in the import map, the take and its
loop as base64 payloads (:mod:`.payload`), the figures as JSON.  It opens offline in any current browser.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Iterator
from pathlib import Path

from ..text import json_text
from .payload import motion_payload_pieces

STATIC = Path(__file__).parent / "static"
#: modules the report page loads: import-map name -> file under static/
MODULES = {
    "three/core": "vendor/three.core.min.js",
    "three": "vendor/three.module.min.js",
    "three/addons/OrbitControls.js": "vendor/OrbitControls.js",
    "mocycle/payload.js": "payload.js",
    "mocycle/phase.js": "phase.js",
    "mocycle/viewer.js": "viewer.js",
    "mocycle/player.js": "player.js",
    "mocycle/report.js": "report.js",
}
#: placeholders in the page text where the payload and the motions' base64 texts are streamed in
MARK = {"payload": "\x00payload\x00", "take": "\x00take\x00", "loop": "\x00loop\x00"}
CORE_IMPORT = '"./three.core.min.js"'  # three.module.min.js imports the core by a relative path


def _player_markup() -> str:
    """The studio page's player (viewer, transport, phase strip), as ``static/index.html`` writes it: one
    markup for both pages, which ``player.js`` and ``report.js`` find by the same ids."""
    page = (STATIC / "index.html").read_text(encoding="utf-8")
    start, end = page.index("<!-- player:"), page.index("<!-- /player -->")
    return page[page.index("\n", start) + 1:end].rstrip()


def _module_text(name: str) -> str:
    text = (STATIC / MODULES[name]).read_text(encoding="utf-8")
    if name == "three":
        # a data: URL cannot resolve a relative import: name the core through the import map instead
        if CORE_IMPORT not in text:
            raise RuntimeError(f"vendored three.module.min.js no longer imports {CORE_IMPORT}")
        text = text.replace(CORE_IMPORT, '"three/core"')
    return text


def _data_url(text: str) -> str:
    return "data:text/javascript;base64," + base64.b64encode(text.encode()).decode()


def build_report(title: str, take, loop_report=None, reason: str | None = None) -> str:
    """The HTML text: ``take`` (a Motion) and, when there is one, the ``tasks.loop`` report of its loop (a loop
    with failed checks, made with ``force``, is shown under a banner naming them)."""
    return "".join(report_pieces(title, take, loop_report, reason))


def _base64(pieces) -> Iterator[str]:
    """The base64 text of the bytes ``pieces`` joined, piece by piece (each cut at a multiple of 3 bytes)."""
    rest = b""
    for piece in pieces:
        data = rest + piece
        cut = len(data) - len(data) % 3
        if cut:
            yield base64.b64encode(data[:cut]).decode("ascii")
        rest = data[cut:]
    if rest:
        yield base64.b64encode(rest).decode("ascii")


def report_pieces(title: str, take, loop_report=None, reason: str | None = None) -> Iterator[str]:
    """:func:`build_report` as an iterator of text pieces (for :func:`~mocycle.io.atomic.atomic_write`): the
    motions' base64 payloads are made a block of frames at a time, never held whole."""
    from .library import loop_summary

    motions = {"take": (take, {"name": title})}
    data: dict = {"title": title, "take": MARK["take"], "reason": reason}
    if loop_report is not None:
        from .review import loop_view, strip_excitation, strip_parts, take_phase

        facts = loop_report.facts
        view, view_facts = loop_view(loop_report)  # phase-aligned with the take, repeated with root motion
        motions["loop"] = (view, {"name": "loop"})
        data.update(loop=MARK["loop"], view=view_facts,
                    summary=loop_summary(facts), metrics=facts["metrics"], options={
                        **{k: facts.get(k) for k in ("method", "model", "harmonics", "time_axis", "root")},
                        "feet": facts["feet"]["mode"]},
                    phase=take_phase(loop_report), excitation=strip_excitation(loop_report),
                    parts=strip_parts(loop_report), warnings=list(loop_report.warnings),
                    failed_checks=facts["failed_checks"])
    imports = {name: _data_url(_module_text(name)) for name in MODULES}
    # in a <script> element "<!--" followed by "<script" swallows the rest of the page, "</script" ends it: no
    # "<", ">" or "&" in the JSON (JSON escapes them), whatever a title or a name holds
    # (strict JSON: a figure that could not be measured, NaN, is null)
    payload = json_text(data, indent=None).replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    css = (STATIC / "studio.css").read_text(encoding="utf-8")
    page = f"""<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{html.escape(title)} · mocycle report</title>
<link rel="icon" href="data:,">
<style>{css}
main {{ grid-template-columns: minmax(420px, 1fr) 360px; }}
</style>
<script type="importmap">{json.dumps({"imports": imports})}</script>
</head>
<body>
<header><h1>mocycle report</h1><span>{html.escape(title)}</span><span id="status"></span></header>
<main>
  <section>
{_player_markup()}
    <form><label>view <select id="layout"><option value="side">side by side</option>
      <option value="overlay">overlaid</option><option value="take">take only</option>
      <option value="loop">loop only</option></select></label>
      <label><input id="follow" type="checkbox" checked> follow</label></form>
  </section>
  <section><div id="banner" class="banner" data-testid="banner" hidden></div>
    <div id="metrics" data-testid="metrics"></div></section>
</main>
<script id="report-data" type="application/json">{MARK["payload"]}</script>
<script type="module">
import {{ startReport }} from "mocycle/report.js";
startReport(JSON.parse(document.getElementById("report-data").textContent));
</script>
</body>
</html>
"""
    head, tail = page.split(MARK["payload"])
    yield head
    # the payload's JSON with each motion's base64 text streamed where its mark stands
    for name, (motion, extra) in motions.items():
        before, payload = payload.split(json.dumps(MARK[name]), 1)
        yield before + '"'
        yield from _base64(motion_payload_pieces(motion, extra))
        yield '"'
    yield payload
    yield tail
