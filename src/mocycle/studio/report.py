"""``mocycle report``: one self-contained HTML file (viewer, loop, phase strip, metrics), no server needed.

Everything is inline: three.js and the page's modules as ``data:`` URLs in the import map, the take and its
loop as base64 payloads (:mod:`.payload`), the figures as JSON.  It opens offline in any current browser.
"""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

from .payload import motion_payload

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
CORE_IMPORT = '"./three.core.min.js"'  # three.module.min.js imports the core by a relative path


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
    from .library import loop_summary

    data: dict = {"title": title, "take": base64.b64encode(motion_payload(take, {"name": title})).decode(),
                  "reason": reason}
    if loop_report is not None:
        from .review import loop_view

        facts = loop_report.facts
        view, view_facts = loop_view(loop_report)  # phase-aligned with the take, repeated with root motion
        data.update(loop=base64.b64encode(motion_payload(view, {"name": "loop"})).decode(), view=view_facts,
                    summary=loop_summary(facts), metrics=facts["metrics"], options={
                        **{k: facts.get(k) for k in ("method", "model", "harmonics", "time_axis", "root")},
                        "feet": facts["feet"]["mode"]},
                    phase=[round(float(v), 4) for v in loop_report.result.periodic.coords],
                    excitation=facts["excitation"], warnings=list(loop_report.warnings),
                    failed_checks=facts["failed_checks"])
    imports = {name: _data_url(_module_text(name)) for name in MODULES}
    payload = json.dumps(data, allow_nan=False).replace("</", "<\\/")
    css = (STATIC / "studio.css").read_text(encoding="utf-8")
    return f"""<!doctype html>
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
    <div id="viewer" data-testid="viewer"></div>
    <div class="transport">
      <button id="play" type="button" data-testid="play">▶</button>
      <input id="scrub" type="range" min="0" max="0" value="0" step="1" data-testid="scrub">
      <span id="frame"></span>
    </div>
    <canvas id="phase" data-testid="phase"></canvas>
    <form><label>view <select id="layout"><option value="side">side by side</option>
      <option value="overlay">overlaid</option><option value="take">take only</option>
      <option value="loop">loop only</option></select></label>
      <label><input id="follow" type="checkbox" checked> follow</label></form>
  </section>
  <section><div id="banner" class="banner" data-testid="banner" hidden></div>
    <div id="metrics" data-testid="metrics"></div></section>
</main>
<script id="report-data" type="application/json">{payload}</script>
<script type="module">
import {{ startReport }} from "mocycle/report.js";
startReport(JSON.parse(document.getElementById("report-data").textContent));
</script>
</body>
</html>
"""
