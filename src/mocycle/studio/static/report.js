// mocycle report: the take and its loop in one self-contained page (data inline).
import { Viewer } from "mocycle/viewer.js";
import { Player } from "mocycle/player.js";
import { decode } from "mocycle/payload.js";

const $ = (id) => document.getElementById(id);
const fmt = (v, d = 2) => (v == null || !isFinite(v) ? "–" : Number(v).toFixed(d));
// a figure with its unit, or "not measured" (null: what the loop's facts could not measure)
const measured = (v, d, unit) => (v == null || !isFinite(v) ? "not measured" : `${Number(v).toFixed(d)} ${unit}`);

function fromBase64(text) {
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  return decode(bytes.buffer);
}

export function startReport(data) {
  const S = (window.__studio = { ready: false, stats: { scrub: [], hover: [], draw: [], strokes: [], firstRender_ms: [] } });
  const viewer = new Viewer($("viewer"));
  const player = new Player(viewer, { play: $("play"), scrub: $("scrub"), label: $("frame"), strip: $("phase") }, S.stats);
  S.viewer = viewer; S.player = player;
  player.setMain(fromBase64(data.take), "take");
  if (data.loop) {
    const loop = fromBase64(data.loop);
    loop.header.cycle_frames = data.view.cycle_frames;
    player.setLoop(loop, data.view.loop_frame);
    player.setPhase(data.phase, data.excitation, data.parts);
  }
  $("layout").addEventListener("change", () => player.setLayout($("layout").value));
  $("follow").addEventListener("change", () => { viewer.follow = $("follow").checked; });
  const rows = [];
  if (data.summary) {
    const l = data.summary, m = data.metrics;
    rows.push(["period", `${fmt(l.period_frames, 1)} frames (${fmt(l.period_s)} s)`], ["loop", `${l.cycle_frames} frames`],
      ["seam jump, pose / velocity", `${fmt(l.seam_pose)} / ${fmt(l.seam_velocity)} × a frame's step (about 1 is seamless)`],
      ["foot skate, loop / take", l.skate == null && l.input_skate == null ? "not measured (no feet found by name)" :
        `${measured(l.skate, 2, "units/s")} / ${measured(l.input_skate, 2, "units/s")}`],
      ["template error", `${fmt(m.template_error, 4)} rad`], ["jerk, loop / take", fmt(m.jerk_ratio)],
      ["failed checks", data.failed_checks.map((c) => `${c.check}: ${c.reason}`).join("; ") || "none"]);
    for (const [k, v] of Object.entries(data.options)) rows.push([k, v ?? "–"]);
    for (const w of data.warnings) rows.push(["warning", w]);
  } else rows.push(["no loop", data.reason || ""]);
  if (data.failed_checks && data.failed_checks.length) {
    // made with --force: the page says first that this loop fails its checks
    const b = $("banner");
    b.hidden = false;
    b.textContent = `FORCED: ${data.summary.refusal_line} (checks ${data.failed_checks.map((c) => c.check).join(", ")}); ` +
      "shown only because the report was made with --force: " + data.failed_checks.map((c) => `${c.check}: ${c.reason}`).join("; ");
  }
  const esc = (s) => String(s).replace(/[&<>]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;" }[c]));
  $("metrics").innerHTML = `<h2>${esc(data.title)}</h2><table>${rows.map(([k, v]) => `<tr><th>${esc(k)}</th><td>${esc(v)}</td></tr>`).join("")}</table>`;
  player.play();
  S.ready = true;
}
