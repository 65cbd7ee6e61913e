// The 3-D view: skeletons (bones as cylinders, joints as spheres), a floor grid, an orbit camera.
import * as THREE from "three";
import { OrbitControls } from "three/addons/OrbitControls.js";

const UP = new THREE.Vector3(0, 1, 0);

export class Figure {
  constructor(viewer, header, color) {
    this.header = header;
    this.parents = header.parents;
    // joints the server found detached from the body (studio/payload.py: a still joint above the body, farther
    // from it than any bone of the body, e.g. a root left at the room's origin): neither they nor their bones
    const hidden = new Set(header.hidden || []);
    this.points = this.parents.map((_, i) => i).filter((i) => !hidden.has(i));
    this.bones = this.parents.map((p, i) => [p, i]).filter(([p, i]) => p >= 0 && !hidden.has(p) && !hidden.has(i));
    const s = viewer.scaleOf(header);
    this.group = new THREE.Group();
    // the take's vertical goes to +Y, its floor to y = 0, its height to about 1.7 scene units
    this.group.quaternion.setFromUnitVectors(new THREE.Vector3(...header.up), UP);
    this.group.scale.setScalar(s);
    this.group.position.y = -header.floor * s;
    this.offset = new THREE.Group();
    this.offset.add(this.group);
    const radius = 0.022 / s;
    const mat = new THREE.MeshStandardMaterial({ color, roughness: 0.55, metalness: 0.05 });
    this.boneMesh = new THREE.InstancedMesh(new THREE.CylinderGeometry(radius, radius, 1, 8), mat, this.bones.length);
    this.jointMesh = new THREE.InstancedMesh(new THREE.SphereGeometry(radius * 1.6, 10, 8), mat, this.points.length);
    for (const m of [this.boneMesh, this.jointMesh]) { m.frustumCulled = false; this.group.add(m); }
    viewer.scene.add(this.offset);
    this._m = new THREE.Matrix4(); this._q = new THREE.Quaternion(); this._v = new THREE.Vector3();
    this._a = new THREE.Vector3(); this._b = new THREE.Vector3(); this._s = new THREE.Vector3();
  }

  // positions: Float32Array (P × 3) in file units
  setPose(P) {
    const { _m, _q, _v, _a, _b, _s } = this;
    _s.set(1, 1, 1);
    this.points.forEach((i, k) => {
      _m.makeTranslation(P[i * 3], P[i * 3 + 1], P[i * 3 + 2]);
      this.jointMesh.setMatrixAt(k, _m);
    });
    this.bones.forEach(([p, c], k) => {
      _a.set(P[p * 3], P[p * 3 + 1], P[p * 3 + 2]);
      _b.set(P[c * 3], P[c * 3 + 1], P[c * 3 + 2]);
      _v.subVectors(_b, _a);
      const len = _v.length();
      _q.setFromUnitVectors(UP, len > 0 ? _v.divideScalar(len) : UP);
      _s.set(1, Math.max(len, 1e-6), 1);
      _m.compose(_a.lerp(_b, 0.5), _q, _s);
      this.boneMesh.setMatrixAt(k, _m);
    });
    this.boneMesh.instanceMatrix.needsUpdate = true;
    this.jointMesh.instanceMatrix.needsUpdate = true;
    this.last = P;
  }

  visible(v) { this.offset.visible = v; }

  // see-through (overlaid on another figure) or solid
  seeThrough(on) {
    const m = this.boneMesh.material;
    m.transparent = on; m.opacity = on ? 0.45 : 1; m.depthWrite = !on; m.needsUpdate = true;
  }

  dispose(viewer) {
    viewer.scene.remove(this.offset);
    this.boneMesh.geometry.dispose(); this.jointMesh.geometry.dispose(); this.boneMesh.material.dispose();
  }
}

// The floor: lines every `step` units out to `half` units, drawn as short pieces (SwiftShader drops long lines)
function floorGrid(half, step) {
  const v = [];
  for (let a = -half; a <= half + 1e-9; a += step) {
    for (let b = -half; b < half - 1e-9; b += step) {
      v.push(a, 0, b, a, 0, b + step, b, 0, a, b + step, 0, a);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.Float32BufferAttribute(v, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xa3a9b4 }));
}

export class Viewer {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf4f5f7);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.05, 500);
    this.camera.position.set(3.0, 2.4, 4.4);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0, 0.9, 0);
    this.controls.addEventListener("change", () => this.render());
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8890a0, 2.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(3, 6, 4);
    this.scene.add(sun);
    const grid = floorGrid(12, 0.5);
    this.scene.add(grid);
    this.grid = grid;
    this.figures = {};
    this.follow = true;
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  scaleOf(header) { return 1.7 / (header.height || 1); }

  resize() {
    const w = this.container.clientWidth || 300, h = this.container.clientHeight || 200;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  setFigure(name, header, color) {
    if (this.figures[name]) this.figures[name].dispose(this);
    this.figures[name] = header ? new Figure(this, header, color) : undefined;
    return this.figures[name];
  }

  // side by side (the second figure 1.2 units to the right) or overlaid
  layout(sideBySide) {
    const b = this.figures.loop;
    if (b) b.offset.position.x = sideBySide ? 1.2 : 0;
  }

  // keep the camera on figure `name`'s travel joint (horizontally)
  track(name) {
    const f = this.figures[name];
    if (!this.follow || !f || !f.last) return;
    const p = new THREE.Vector3();
    const t = f.header.travel, P = f.last;
    p.set(P[t * 3], P[t * 3 + 1], P[t * 3 + 2]);
    f.group.updateMatrixWorld(true);
    p.applyMatrix4(f.group.matrixWorld);
    const dx = p.x - this.controls.target.x, dz = p.z - this.controls.target.z;
    if (Math.abs(dx) + Math.abs(dz) < 1e-6) return;
    this.controls.target.x += dx; this.controls.target.z += dz;
    this.camera.position.x += dx; this.camera.position.z += dz;
    this.grid.position.x = Math.round(this.controls.target.x); this.grid.position.z = Math.round(this.controls.target.z);
    this.controls.update();
  }

  render() { this.renderer.render(this.scene, this.camera); }
}
