// mocycle studio: the library, the review (viewer, loop, phase strip, options) and the authoring plane.
import { Viewer } from "mocycle/viewer.js";
import { Player } from "mocycle/player.js";
import { Plane } from "mocycle/plane.js";
import { PosePlane } from "mocycle/spatial.js";
import { fetchPayload, token } from "mocycle/payload.js";

const $ = (id) => document.getElementById(id);
const S = (window.__studio = { ready: false, stats: { scrub: [], hover: [], draw: [], strokes: [], firstRender_ms: [] } });

// every request carries the server's token (studio/guard.py refuses a POST or DELETE without it)
async function json(url, body, method) {
  const headers = { "X-Mocycle-Token": token() };
  const r = await fetch(url, body === undefined ? { method: method || "GET", headers } :
    { method: method || "POST", headers: { ...headers, "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const out = await r.json().catch(() => ({}));
  if (!r.ok) throw new Error(out.error || `${url}: ${r.status}`);
  return out;
}

// an element built from data: text is always set as text (names from files are never parsed as HTML)
function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v == null || v === false) continue;
    if (k === "class") el.className = v; else el.setAttribute(k, v);
  }
  for (const c of children.flat()) if (c != null && c !== false) el.append(c instanceof Node ? c : String(c));
  return el;
}

function status(text, isError = false) { const el = $("status"); el.textContent = text; el.classList.toggle("error", isError); }
const fmt = (v, d = 2) => (v == null || !isFinite(v) ? "–" : Number(v).toFixed(d));
// a figure with its unit, or "not measured" (the server sends null for what it could not measure)
const measured = (v, d, unit) => (v == null || !isFinite(v) ? "not measured" : `${Number(v).toFixed(d)} ${unit}`);
const seam = (v) => measured(v, 2, "× a frame's step");
// a line, and the whole text one click away when the line is only its start (the server cut it: tasks.words)
function said(line, whole, cls) {
  if (!whole || line === whole) return h("span", { class: cls }, line);
  return h("details", { class: cls }, h("summary", {}, line), h("div", { class: "reason" }, whole));
}

// ---------------------------------------------------------------- library
function renderLibrary(data) {
  $("progress").value = data.total ? data.done / data.total : 1;
  $("progress-label").textContent = `analysed ${data.done} / ${data.total}`;
  const list = $("takes");
  for (const t of data.takes) {
    let row = [...list.children].find((r) => r.dataset.id === t.id);
    if (!row) {
      row = document.createElement("div");
      row.className = "take"; row.dataset.id = t.id;
      row.setAttribute("data-testid", "take");
      row.addEventListener("click", () => openTake(t.id));
      list.appendChild(row);
    }
    row.classList.toggle("current", t.id === S.take);
    const f = t.facts || {};
    // a loop that fails its checks is refused (as mocycle loop refuses it): its status and the reason
    // a loop that fails its checks: refused in plain words, each check's reason (with its numbers) one click away
    const loops = t.loops.map((l) => h("li", { class: l.refused ? "refused" : "ok", "data-state": l.refused ? "refused" : "ok" },
      l.kind ? `${l.kind} ${l.frames ? `${l.frames[0]}–${l.frames[1]} ` : ""}· ` : "",
      `period ${fmt(l.period_s)} s (${fmt(l.period_frames, 1)} frames) · seam ${seam(l.seam_pose)} · foot skate ${measured(l.skate, 2, "units/s")}`,
      l.refused ? said(`refused: ${l.refusal_line}`, `refused: ${l.refusal_line} (${l.refusal})`, "bad") : null));
    const state = t.status === "done" ? "" : ["failed", "refused"].includes(t.status) ? said(t.error_line, t.error, "bad") : h("span", { class: "busy" }, `${t.status}…`);
    row.dataset.state = t.status !== "done" ? t.status : !t.loops.length ? "no-loop" : t.loops.some((l) => !l.refused) ? "ok" : "refused";
    row.replaceChildren(h("div", { class: "name" }, t.name),
      h("div", { class: "facts" }, `${f.frames ?? "…"} frames · ${fmt(f.fps, 0)} fps · ${t.status === "done" ? `${t.loops.length} loop${t.loops.length === 1 ? "" : "s"}` : ""} `, state),
      h("ul", { class: "loops" }, loops, t.reason ? h("li", { class: "muted" }, said(`no loop: ${t.reason_line}`, `no loop: ${t.reason}`)) : null));
  }
}

async function pollLibrary() {
  try {
    const data = await json("/api/takes");
    renderLibrary(data);
    S.library = data;
    setTimeout(pollLibrary, data.done < data.total ? 600 : 4000);
  } catch (e) { status(e.message, true); setTimeout(pollLibrary, 4000); }
}

// ---------------------------------------------------------------- review
async function openTake(id) {
  const t0 = performance.now();
  S.take = id;
  // a loop still running (this take's, opened again, or the last take's) is superseded by this opening: its
  // answer, arriving while this take loads, is not shown
  S.loopSeq = (S.loopSeq || 0) + 1;
  if (S.loopRunning) json(`/api/jobs/${S.loopRunning}`, undefined, "DELETE").catch(() => {});
  S.loopRunning = null;
  $("loop-options").elements.force.checked = false;  // force is asked for one take's loop, not kept for the next
  document.querySelectorAll(".take").forEach((r) => r.classList.toggle("current", r.dataset.id === id));
  status("loading the take…");
  const listed = S.library ? S.library.takes.find((t) => t.id === id) : null;
  $("take-name").textContent = listed ? listed.name : "";
  let motion;
  try {
    motion = await fetchPayload(`/api/takes/${id}/motion`);
  } catch (e) {
    // a take that cannot be read: its name and why, nothing of the previous take left to play or author on
    if (S.take !== id) return;
    S.motion = null; S.pose = null; S.plane = null; S.keys = null; S.loopJob = null;
    S.player.clear();
    loopState("failed", `cannot read this take: ${e.message}`);
    $("metrics").replaceChildren();
    setDownloads("loop", null);
    $("plane-status").textContent = "";
    status(e.message, true);
    return;
  }
  if (S.take !== id) return;
  S.player.setLoop(null); S.player.setPhase(null, null);
  S.player.setMain(motion, "take");
  S.stats.firstRender_ms.push({ frames: motion.header.frames, ms: performance.now() - t0 });
  S.motion = motion;
  $("take-name").textContent = motion.header.name;
  status("");
  S.player.play();
  runLoop();
  loadPlane();
}

function formValues(form) {
  const out = {};
  for (const el of form.querySelectorAll("[name]")) out[el.name] = el.type === "checkbox" ? el.checked : el.value;
  return out;
}

async function waitJob(job, onProgress) {
  S.jobs = S.jobs || {};
  for (;;) {
    const j = await json(`/api/jobs/${job.id}`);
    if (onProgress) onProgress(j);
    if (["done", "failed", "cancelled", "refused"].includes(j.status)) return j;
    await new Promise((r) => setTimeout(r, 150));
  }
}

function setDownloads(prefix, base) {
  for (const ext of ["bvh", "glb"]) {
    const a = $(`${prefix}-${ext}`);
    if (base) a.href = `${base}.${ext}`; else a.removeAttribute("href");
  }
}

function loopState(state, ...content) {
  const el = $("loop-status");
  el.dataset.state = state; el.replaceChildren(...content);
  el.classList.toggle("bad", state === "refused" || state === "forced");
}

async function runLoop() {
  const id = S.take;
  if (!id) return;
  // a newer loop supersedes the one still running (its job is cancelled, its answer ignored)
  const seq = S.loopSeq = (S.loopSeq || 0) + 1;
  if (S.loopRunning) json(`/api/jobs/${S.loopRunning}`, undefined, "DELETE").catch(() => {});
  S.loopRunning = null;
  loopState("running", "looping…");
  $("metrics").replaceChildren();
  setDownloads("loop", null);
  try {
    const job = await json(`/api/takes/${id}/loop`, formValues($("loop-options")));
    if (seq !== S.loopSeq) { json(`/api/jobs/${job.id}`, undefined, "DELETE").catch(() => {}); return; }
    S.loopRunning = job.id;
    const j = await waitJob(job);
    if (seq !== S.loopSeq) return;
    S.loopRunning = null;
    if (S.take !== id) return;
    S.loopJob = j;
    if (j.status === "refused") {
      // refused as mocycle loop refuses it: no loop shown, nothing to download unless asked with force
      S.player.setLoop(null); S.player.setPhase(null, null);
      const force = h("button", { id: "loop-force", type: "button", "data-testid": "force-loop" }, "Show and download anyway (force)");
      loopState("refused", `refused: ${j.error_line} `, force);  // each check's reason is in the table below
      force.addEventListener("click", () => { $("loop-options").elements.force.checked = true; runLoop(); });
      $("metrics").replaceChildren(h("table", {}, j.result.failed_checks.map((c) => h("tr", {}, h("th", {}, `failed check: ${c.check}`), h("td", {}, c.reason)))));
      return;
    }
    if (j.status !== "done") { loopState("failed", j.error ? said(j.error_line, j.error) : j.status); S.player.setLoop(null); return; }
    const loop = await fetchPayload(`/api/jobs/${j.id}/motion`);
    if (S.take !== id || seq !== S.loopSeq) return;
    loop.header.cycle_frames = j.result.view.cycle_frames;
    S.player.setLoop(loop, j.result.view.loop_frame);
    S.player.setPhase(j.result.phase, j.result.excitation, j.result.parts);
    const l = j.result.loop, failed = j.result.failed_checks;
    const text = `loop of ${l.cycle_frames} frames · period ${fmt(l.period_s)} s · made in ${fmt(j.result.seconds)} s`;
    if (failed.length) loopState("forced", `FORCED: ${l.refusal_line} (checks ${failed.map((c) => c.check).join(", ")}); shown because you asked · ${text}`);
    else loopState("ok", text);
    const row = (k, v, cls) => h("tr", {}, h("th", {}, k), h("td", { class: cls }, v));
    $("metrics").replaceChildren(h("table", {},
      row("period", `${fmt(l.period_frames, 1)} frames (${fmt(l.period_s)} s)`),
      row("seam jump, pose / velocity", `${fmt(l.seam_pose)} / ${fmt(l.seam_velocity)} × a frame's step (about 1 is seamless)`),
      row("foot skate, loop / take", l.skate == null && l.input_skate == null ? "not measured (no feet found by name)" :
        `${measured(l.skate, 2, "units/s")} / ${measured(l.input_skate, 2, "units/s")}`),
      row("failed checks", failed.map((c) => `${c.check}: ${c.reason}`).join("; ") || "none", failed.length ? "bad" : null),
      j.result.warnings.map((w) => row("warning", w))));
    setDownloads("loop", `/api/jobs/${j.id}/loop`);
  } catch (e) { if (seq === S.loopSeq) { loopState("failed", e.message); S.player.setLoop(null); } }
}

// the loop form: one control per field the loop's spec names for the studio (schema.forms.loop), made from the
// field's schema (a choice: a list; a whole number: a number box; on/off: a box to tick)
function control(name, p, value) {
  let el;
  if (p.enum) {
    el = document.createElement("select");
    for (const v of p.enum) el.add(new Option(v, v, false, v === value));
  } else if (p.type === "boolean") {
    el = document.createElement("input"); el.type = "checkbox"; el.checked = !!value;
  } else {
    el = document.createElement("input");
    el.type = p.type === "integer" || p.type === "number" ? "number" : "text";
    if (p.type === "number") el.step = "any";
    if (p.minimum !== undefined) el.min = p.minimum;
    if (p.maximum !== undefined) el.max = p.maximum;
    el.value = value ?? "";
  }
  el.name = name; el.title = p.description;
  return el;
}

// the studio's own starting values where they differ from the task's defaults: loops moving on, three cycles
// long; a plane with more keyframes than the thesis' 3 %, optimised
const STUDIO_DEFAULTS = { loop: { root: "motion", cycles: 3 }, plane: { ratio: 0.05, optimize: true } };

function buildForm(schema, form, box) {
  for (const name of schema.forms[form]) {
    const p = schema[form].properties[name];
    const label = document.createElement("label");
    label.append(name.replace("_", " ") + " ", control(name, p, STUDIO_DEFAULTS[form]?.[name] ?? p.default));
    $(box).appendChild(label);
  }
}

function buildOptions(schema) {
  buildForm(schema, "loop", "loop-fields");
  buildForm(schema, "plane", "plane-fields");
}

// the plane form's fields as the plane's query (on/off fields as 1 or 0)
function planeQuery() {
  const q = new URLSearchParams();
  for (const el of $("plane-form").querySelectorAll("[name]")) q.set(el.name, el.type === "checkbox" ? (el.checked ? "1" : "0") : el.value);
  return q;
}

// ---------------------------------------------------------------- authoring plane
async function loadPlane() {
  const id = S.take;
  const q = planeQuery();
  $("plane-status").textContent = "projecting…";
  try {
    const plane = await fetchPayload(`/api/takes/${id}/plane?${q}`);
    if (S.take !== id) return;
    S.plane = plane;
    S.pose = new PosePlane(plane);
    S.keys = plane.header.keyframes.slice();
    const P = plane.arrays.points;
    S.markers = S.keys.map((k) => [P[2 * k], P[2 * k + 1]]);
    S.pose.setMarkers(S.markers);
    S.planeView.setData(P, S.keys, S.markers);
    S.strokeId = null; for (const id of ["export", "export-glb"]) { $(id).removeAttribute("href"); $(id).classList.add("disabled"); }
    $("plane-status").textContent = `${plane.header.projection}, ${S.keys.length} keyframes, stress ${plane.header.stress == null ? "–" : Number(plane.header.stress).toPrecision(3)}`;
  } catch (e) { $("plane-status").textContent = e.message; }
}

function showPoseAt(x, y, list) {
  if (!S.pose) return;
  const t0 = performance.now();
  S.player.showPose(S.pose.pose(x, y), S.plane.header);
  S.stats[list].push(performance.now() - t0);
}

async function sendStroke(points, times) {
  const id = S.take;
  const body = { keyframes: S.keys, markers: S.markers, points, times_s: times };
  $("plane-status").textContent = "authoring…";
  try {
    const t0 = performance.now();
    const r = await json(`/api/takes/${id}/strokes`, body);
    const motion = await fetchPayload(`/api/strokes/${r.id}/motion`);
    S.stats.strokes.push({ frames: r.frames, server_ms: r.server_ms, round_trip_ms: performance.now() - t0 });
    S.strokeId = r.id;
    S.player.setMain(motion, "authored");
    S.player.play();
    $("export").href = `/api/strokes/${r.id}.bvh`; $("export-glb").href = `/api/strokes/${r.id}.glb`;
    for (const id of ["export", "export-glb"]) $(id).classList.remove("disabled");
    $("plane-status").textContent = `authored ${r.frames} frames (${fmt(r.duration_s)} s) · server ${fmt(r.server_ms, 0)} ms`;
  } catch (e) { $("plane-status").textContent = e.message; }
}

async function relayout() {
  const id = S.take;
  const previous = S.relayoutJob;
  S.relayoutJob = null;
  if (previous) json(`/api/jobs/${previous}`, undefined, "DELETE").catch(() => {});
  $("relayout-progress").value = 0; $("relayout-box").classList.add("busy");
  try {
    const job = await json(`/api/takes/${id}/relayout`, { keyframes: S.keys, markers: S.markers, optimize: $("plane-form").elements.optimize.checked });
    S.relayoutJob = job.id;
    const j = await waitJob(job, (s) => { if (S.relayoutJob === job.id) $("relayout-progress").value = s.progress; });
    if (S.relayoutJob !== job.id || S.take !== id) return;  // a newer drag took over (its box stays)
    S.relayoutJob = null;
    if (j.status === "done") {
      const pts = Float32Array.from(j.result.points.flat());
      S.planeView.setData(pts, S.keys, S.markers, false);
      S.relayouts = (S.relayouts || 0) + 1;
      $("plane-status").textContent = `re-laid out (RBFP + Algorithm 12: error ${fmt(j.result.error_before, 3)} → ${fmt(j.result.error_after, 3)}, ${fmt(j.result.seconds)} s)`;
    } else $("plane-status").textContent = `re-layout ${j.status}${j.error ? ": " + j.error : ""}`;
  } finally { if (!S.relayoutJob) $("relayout-box").classList.remove("busy"); }
}

function planeHandlers() {
  return {
    hover: (x, y) => showPoseAt(x, y, "hover"),
    leave: () => { if (S.player.main) S.player.setMain(S.player.main, S.player.kind); },
    strokePoint: (x, y) => showPoseAt(x, y, "draw"),
    stroke: (points, times) => sendStroke(points, times),
    markerMoved: (k, x, y) => { S.markers[k] = [x, y]; S.pose.setMarkers(S.markers); showPoseAt(x, y, "draw"); },
    markerDropped: () => relayout(),
    markerClicked: (k) => {
      if (S.keys.length <= 4) { $("plane-status").textContent = "at least 4 keyframes stay"; return; }
      const rows = S.keys.map((_, i) => i).filter((i) => i !== k);
      S.pose.keep(rows);
      S.keys = rows.map((i) => S.keys[i]); S.markers = rows.map((i) => S.markers[i]);
      S.pose.setMarkers(S.markers);
      S.planeView.setData(S.planeView.points, S.keys, S.markers, false);
      relayout();
    },
  };
}

export async function startStudio() {
  try {
    const viewer = new Viewer($("viewer"));
    S.viewer = viewer;
    S.player = new Player(viewer, { play: $("play"), scrub: $("scrub"), label: $("frame"), strip: $("phase") }, S.stats);
    S.planeView = new Plane($("plane"), planeHandlers());
    buildOptions(await json("/api/options"));
    $("loop-options").addEventListener("submit", (e) => { e.preventDefault(); runLoop(); });
    $("layout").addEventListener("change", () => S.player.setLayout($("layout").value));
    $("follow").addEventListener("change", () => { viewer.follow = $("follow").checked; });
    $("plane-form").addEventListener("submit", (e) => { e.preventDefault(); loadPlane(); });
    $("cancel-relayout").addEventListener("click", () => { if (S.relayoutJob) json(`/api/jobs/${S.relayoutJob}`, undefined, "DELETE"); });
    $("grid-toggle").addEventListener("click", () => $("takes").classList.toggle("grid"));
    // test and measurement hooks
    S.planePixel = (x, y) => { const r = $("plane").getBoundingClientRect(); const [px, py] = S.planeView.toPixel(x, y); return [r.left + px, r.top + py]; };
    S.framePixel = (i) => S.planePixel(S.planeView.points[2 * i], S.planeView.points[2 * i + 1]);
    S.markerPixel = (k) => S.planePixel(...S.markers[k]);
    S.mainPose = () => Array.from(viewer.figures.main.last);
    await pollLibrary();
    if (S.library && S.library.takes.length) await openTake(S.library.takes[0].id);
    S.ready = true;
  } catch (e) { status(e.message, true); console.error(e); }
}
