// The authoring plane (thesis 002, chapter 6): every pose as a point coloured by time (red → green → blue),
// keyframes as markers.  Hover shows the back-projected pose, press-and-drag draws a timed stroke,
// dragging a marker moves it, clicking a marker removes it.
const HIT = 9; // px

export function timeColour(u) {
  // red → green → blue as in the thesis' Figure 6.2
  const h = 240 * Math.min(Math.max(u, 0), 1);
  return `hsl(${h}, 85%, 45%)`;
}

export class Plane {
  constructor(canvas, handlers) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.h = handlers; // {hover(x, y), leave(), strokePoint(x, y), stroke(points, times_s), markerMoved(k, x, y), markerDropped(k), markerClicked(k)}
    this.points = null; this.keys = []; this.markers = []; this.stroke = null; this.drawn = null; this.hover = null;
    this.drag = null;
    new ResizeObserver(() => this.draw()).observe(canvas);
    canvas.addEventListener("pointerdown", (e) => this.down(e));
    canvas.addEventListener("pointermove", (e) => this.move(e));
    canvas.addEventListener("pointerup", (e) => this.up(e));
    canvas.addEventListener("pointerleave", () => { if (!this.drag && !this.stroke) { this.hover = null; this.draw(); this.h.leave(); } });
  }

  // points: Float32Array (T × 2); keys: keyframe indices; markers: [[x, y]] (their places)
  setData(points, keys, markers, refit = true) {
    this.points = points; this.keys = keys.slice(); this.markers = markers.map((m) => m.slice());
    if (refit || !this.view) { this.fit(); this.drawn = null; this.hover = null; }
    this.draw();
  }

  fit() {
    const P = this.points, T = P.length / 2;
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (let i = 0; i < T; i++) {
      x0 = Math.min(x0, P[2 * i]); x1 = Math.max(x1, P[2 * i]); y0 = Math.min(y0, P[2 * i + 1]); y1 = Math.max(y1, P[2 * i + 1]);
    }
    for (const [x, y] of this.markers) { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
    const span = Math.max(x1 - x0, y1 - y0, 1e-9);
    this.view = { cx: (x0 + x1) / 2, cy: (y0 + y1) / 2, span: span * 1.12 };
  }

  size() {
    const r = this.canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    if (this.canvas.width !== Math.round(r.width * dpr) || this.canvas.height !== Math.round(r.height * dpr)) {
      this.canvas.width = Math.round(r.width * dpr); this.canvas.height = Math.round(r.height * dpr);
    }
    return { w: r.width, h: r.height, dpr };
  }

  // plane ↔ canvas pixels (CSS px from the canvas' top-left corner); y grows upwards on the plane
  toPixel(x, y) {
    const { w, h } = this.size(), s = Math.min(w, h) / this.view.span;
    return [w / 2 + (x - this.view.cx) * s, h / 2 - (y - this.view.cy) * s];
  }

  toPlane(px, py) {
    const { w, h } = this.size(), s = Math.min(w, h) / this.view.span;
    return [this.view.cx + (px - w / 2) / s, this.view.cy - (py - h / 2) / s];
  }

  local(e) {
    const r = this.canvas.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  markerAt(px, py) {
    let best = -1, bestD = HIT;
    this.markers.forEach(([x, y], k) => {
      const [mx, my] = this.toPixel(x, y), d = Math.hypot(mx - px, my - py);
      if (d < bestD) { bestD = d; best = k; }
    });
    return best;
  }

  down(e) {
    if (!this.points || e.button !== 0) return;
    this.canvas.setPointerCapture(e.pointerId);
    const [px, py] = this.local(e);
    const k = this.markerAt(px, py);
    if (k >= 0) { this.drag = { k, moved: false, x: px, y: py }; return; }
    const [x, y] = this.toPlane(px, py);
    this.stroke = { points: [[x, y]], times: [e.timeStamp / 1000] };
    this.drawn = null;
    this.h.strokePoint(x, y);
    this.draw();
  }

  move(e) {
    if (!this.points) return;
    const [px, py] = this.local(e);
    const [x, y] = this.toPlane(px, py);
    if (this.drag) {
      if (!this.drag.moved && Math.hypot(px - this.drag.x, py - this.drag.y) < 3) return;
      this.drag.moved = true;
      this.markers[this.drag.k] = [x, y];
      this.h.markerMoved(this.drag.k, x, y);
    } else if (this.stroke) {
      const events = e.getCoalescedEvents ? e.getCoalescedEvents() : [e];
      for (const ev of events.length ? events : [e]) {
        const [qx, qy] = this.toPlane(...this.local(ev));
        this.stroke.points.push([qx, qy]); this.stroke.times.push(ev.timeStamp / 1000);
      }
      this.h.strokePoint(x, y);
    } else {
      this.hover = [x, y];
      this.h.hover(x, y);
    }
    this.draw();
  }

  up(e) {
    if (this.drag) {
      const { k, moved } = this.drag;
      this.drag = null;
      if (moved) this.h.markerDropped(k); else this.h.markerClicked(k);
    } else if (this.stroke) {
      const s = this.stroke;
      this.stroke = null;
      this.drawn = s;
      if (s.points.length > 1 && s.times[s.times.length - 1] > s.times[0]) this.h.stroke(s.points, s.times);
    }
    this.draw();
  }

  draw() {
    const { w, h, dpr } = this.size();
    const c = this.ctx;
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    c.clearRect(0, 0, w, h);
    if (!this.points) return;
    const P = this.points, T = P.length / 2;
    c.lineWidth = 1.5;
    for (let i = 1; i < T; i++) {
      const [ax, ay] = this.toPixel(P[2 * i - 2], P[2 * i - 1]), [bx, by] = this.toPixel(P[2 * i], P[2 * i + 1]);
      c.strokeStyle = timeColour(i / (T - 1));
      c.beginPath(); c.moveTo(ax, ay); c.lineTo(bx, by); c.stroke();
    }
    for (let i = 0; i < T; i++) {
      const [x, y] = this.toPixel(P[2 * i], P[2 * i + 1]);
      c.fillStyle = timeColour(i / Math.max(T - 1, 1));
      c.fillRect(x - 1.5, y - 1.5, 3, 3);
    }
    for (const s of [this.drawn, this.stroke]) {
      if (!s) continue;
      c.strokeStyle = "#111"; c.lineWidth = 2.5; c.beginPath();
      s.points.forEach(([x, y], i) => { const [px, py] = this.toPixel(x, y); if (i) c.lineTo(px, py); else c.moveTo(px, py); });
      c.stroke();
    }
    this.markers.forEach(([x, y], k) => {
      const [px, py] = this.toPixel(x, y);
      c.beginPath(); c.arc(px, py, 6, 0, 2 * Math.PI);
      c.fillStyle = timeColour(this.keys[k] / Math.max(T - 1, 1)); c.fill();
      c.lineWidth = 2; c.strokeStyle = "#000"; c.stroke();
    });
    if (this.hover) {
      const [px, py] = this.toPixel(...this.hover);
      c.strokeStyle = "#333"; c.lineWidth = 1;
      c.beginPath(); c.moveTo(px - 7, py); c.lineTo(px + 7, py); c.moveTo(px, py - 7); c.lineTo(px, py + 7); c.stroke();
    }
  }
}
