// The phase strip: the take's steady parts along the top (each a coloured band, its kind written on it, hatched
// grey when it is not looped), the phase of every frame of the part looped (0 → 1 as a grey ramp; null where it
// has none), the excitation regions as bars, the current frame as a line.
const KIND_COLOURS = { straight: "#3c8d5a", left: "#3a6fc4", right: "#b0559a", arms: "#c47a1e", periodic: "#6a6a6a" };

function kindColour(kind) {
  if (/left/.test(kind)) return KIND_COLOURS.left;
  if (/right/.test(kind)) return KIND_COLOURS.right;
  if (/straight/.test(kind)) return KIND_COLOURS.straight;
  return KIND_COLOURS[kind] || "#9a9a9a";
}

export function drawPhaseStrip(canvas, phase, excitation, frame, frames, parts) {
  const r = canvas.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
  canvas.width = Math.round(r.width * dpr); canvas.height = Math.round(r.height * dpr);
  const c = canvas.getContext("2d"), w = r.width, h = r.height;
  c.setTransform(dpr, 0, 0, dpr, 0, 0);
  c.clearRect(0, 0, w, h);
  const T = frames || (phase ? phase.length : 0);
  if (!T) return;
  const x = (i) => (i / Math.max(T - 1, 1)) * w;
  const top = parts && parts.length ? 12 : 0;
  if (top) {
    c.font = "10px sans-serif"; c.textBaseline = "middle";
    for (const p of parts) {
      const [s, e] = p.frames, x0 = x(s), wd = Math.max(x(e) - x(s), 1);
      c.fillStyle = p.loop ? kindColour(p.kind) : "#d4d4d4";
      c.fillRect(x0, 0, wd - 1, top - 2);
      const label = String(p.kind);  // drawn as text on the canvas: never markup
      if (c.measureText(label).width + 4 < wd) { c.fillStyle = p.loop ? "#fff" : "#555"; c.fillText(label, x0 + 2, (top - 2) / 2); }
    }
  }
  if (phase && phase.length) {
    const band = h - 10;
    for (let i = 0; i < phase.length; i++) {
      if (phase[i] == null) continue;
      const v = Math.round(235 - 190 * phase[i]);
      c.fillStyle = `rgb(${v},${v},${Math.min(255, v + 20)})`;
      c.fillRect(x(i), top, Math.max(w / T, 1) + 0.5, band - top);
    }
    c.strokeStyle = "#1f4fa0"; c.lineWidth = 1.2; c.beginPath();
    let drawing = false;
    for (let i = 0; i < phase.length; i++) {
      if (phase[i] == null) { drawing = false; continue; }
      const y = band - phase[i] * (band - top - 2) - 1;
      if (!drawing || Math.abs(phase[i] - phase[i - 1]) > 0.5) c.moveTo(x(i), y); else c.lineTo(x(i), y);
      drawing = true;
    }
    c.stroke();
  }
  c.fillStyle = "#e08a1e";
  for (const [s, e] of excitation || []) c.fillRect(x(s), h - 8, Math.max(x(e) - x(s), 2), 6);
  if (frame != null) { c.fillStyle = "#c0142c"; c.fillRect(x(frame) - 1, 0, 2, h); }
}
