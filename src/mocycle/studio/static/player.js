// The clock, the transport (play, scrub) and the phase strip around a Viewer; poses from per-frame arrays
// (no server round trip while playing or scrubbing).
import { drawPhaseStrip } from "mocycle/phase.js";

export const COLORS = { main: 0x2f6fd0, loop: 0xe0702a, authored: 0x2a9d55 };

export class Player {
  constructor(viewer, els, stats) {
    this.viewer = viewer; this.els = els; this.stats = stats;
    this.main = null; this.loop = null; this.phase = null; this.excitation = null;
    this.playing = false; this.frame = 0; this.t = 0; this.mode = "side";
    els.play.addEventListener("click", () => this.toggle());
    els.scrub.addEventListener("input", () => {
      const t0 = performance.now();
      this.pause();
      this.setFrame(Number(els.scrub.value));
      stats.scrub.push(performance.now() - t0);
    });
    const tick = (now) => {
      if (this.playing && this.main) {
        const dt = this.last ? (now - this.last) / 1000 : 0;
        this.t += dt;
        this.setFrame(Math.floor(this.t * this.main.header.fps) % this.main.header.frames);
      }
      this.last = now;
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  // motion: a decoded payload {header, arrays: {positions}}; kind: "take" or "authored"
  setMain(motion, kind = "take") {
    this.main = motion; this.kind = kind;
    this.viewer.setFigure("main", motion.header, kind === "authored" ? COLORS.authored : COLORS.main);
    this.els.scrub.max = motion.header.frames - 1;
    this.t = 0;
    this.frame = 0;
    this.setLayout(this.mode);
    this.viewer.track("main");
  }

  // motion: the loop as the viewer plays it (one frame per take frame); loopFrames: its cycle frame per frame
  setLoop(motion, loopFrames = null) {
    this.loop = motion; this.loopFrames = loopFrames;
    this.viewer.setFigure("loop", motion ? motion.header : null, COLORS.loop);
    this.setLayout(this.mode);
  }

  // nothing to play (a take that could not be read): no figures, an empty transport
  clear() {
    this.pause();
    this.main = null; this.loop = null; this.loopFrames = null; this.phase = null; this.excitation = null;
    this.viewer.setFigure("main", null); this.viewer.setFigure("loop", null);
    this.els.scrub.max = 0; this.els.scrub.value = 0; this.els.label.textContent = "";
    this.viewer.render();
    this.drawStrip();
  }

  setPhase(phase, excitation, parts) { this.phase = phase; this.excitation = excitation; this.parts = parts || null; this.drawStrip(); }

  setLayout(mode) {
    this.mode = mode;
    const { main, loop } = this.viewer.figures;
    if (main) { main.visible(mode !== "loop"); main.seeThrough(mode === "overlay" && !!loop && this.kind === "take"); }
    if (loop) loop.visible(mode !== "take");
    this.viewer.layout(mode === "side");
    this.setFrame(this.frame);
  }

  drawStrip() {
    if (!this.els.strip) return;
    drawPhaseStrip(this.els.strip, this.kind === "take" ? this.phase : null, this.kind === "take" ? this.excitation : [],
                   this.frame, this.main ? this.main.header.frames : 0, this.kind === "take" ? this.parts : null);
  }

  toggle() { if (this.playing) this.pause(); else this.play(); }
  play() { if (!this.main) return; this.playing = true; this.t = this.frame / this.main.header.fps; this.els.play.textContent = "❚❚"; }
  pause() { this.playing = false; this.els.play.textContent = "▶"; }

  posesAt(motion, f) {
    const P = motion.header.parents.length * 3;
    return motion.arrays.positions.subarray(f * P, (f + 1) * P);
  }

  setFrame(f, updateScrub = true) {
    if (!this.main) return;
    this.frame = f;
    const fig = this.viewer.figures;
    fig.main.setPose(this.posesAt(this.main, f));
    if (this.loop && fig.loop) {
      // the loop as the server placed it: frame f is the cycle frame whose phase is the take's at f, in its
      // pass of the cycle repeated with root motion (studio/review.py)
      fig.loop.setPose(this.posesAt(this.loop, Math.min(f, this.loop.header.frames - 1)));
      fig.loop.visible(this.kind === "take" && this.mode !== "take");
    }
    this.viewer.track("main");
    this.viewer.render();
    if (updateScrub) this.els.scrub.value = f;
    const lf = this.loopFrames && this.kind === "take" && this.loop ? this.loopFrames[f] : null;
    this.els.label.textContent = `${f + 1} / ${this.main.header.frames}` +
      (lf == null ? "" : ` · loop ${Math.floor(lf) + 1} / ${this.loop.header.cycle_frames}`);
    this.drawStrip();
  }

  // a live pose (hovering or drawing on the plane): shown on the main figure at once
  showPose(P, header) {
    this.pause();
    const fig = this.viewer.figures;
    if (!fig.main || fig.main.header !== header) this.viewer.setFigure("main", header, COLORS.authored);
    this.viewer.figures.main.setPose(P);
    if (this.viewer.figures.loop) this.viewer.figures.loop.visible(false);
    this.viewer.render();
  }
}
