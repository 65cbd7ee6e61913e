// The phase strip: the phase of every frame (0 → 1 as a grey ramp), the excitation regions as bars, the
// current frame as a line.
export function drawPhaseStrip(canvas, phase, excitation, frame, frames) {
  const r = canvas.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
  canvas.width = Math.round(r.width * dpr); canvas.height = Math.round(r.height * dpr);
  const c = canvas.getContext("2d"), w = r.width, h = r.height;
  c.setTransform(dpr, 0, 0, dpr, 0, 0);
  c.clearRect(0, 0, w, h);
  const T = frames || (phase ? phase.length : 0);
  if (!T) return;
  const x = (i) => (i / Math.max(T - 1, 1)) * w;
  if (phase && phase.length) {
    const band = h - 10;
    for (let i = 0; i < phase.length; i++) {
      const v = Math.round(235 - 190 * phase[i]);
      c.fillStyle = `rgb(${v},${v},${Math.min(255, v + 20)})`;
      c.fillRect(x(i), 0, Math.max(w / T, 1) + 0.5, band);
    }
    c.strokeStyle = "#1f4fa0"; c.lineWidth = 1.2; c.beginPath();
    for (let i = 0; i < phase.length; i++) {
      const y = band - phase[i] * (band - 2) - 1;
      if (i && Math.abs(phase[i] - phase[i - 1]) > 0.5) c.moveTo(x(i), y); else if (i) c.lineTo(x(i), y); else c.moveTo(x(i), y);
    }
    c.stroke();
  }
  c.fillStyle = "#e08a1e";
  for (const [s, e] of excitation || []) c.fillRect(x(s), h - 8, Math.max(x(e) - x(s), 2), 6);
  if (frame != null) { c.fillStyle = "#c0142c"; c.fillRect(x(frame) - 1, 0, 2, h); }
}
