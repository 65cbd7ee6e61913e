// Igarashi back-projection in the page (thesis 002, eq. 2.1-2.3), the same map as
// mocycle.keyframes.BackProjection: linear kernel |p - L_i| plus the polynomial 1, x, y fitted to
// the keyframes' markers, one output per rotation-matrix entry, then the nearest rotation (Newton polar
// iterations, as rotations.fast_nearest_rotation); forward kinematics to world positions.

// Solve A X = B (A n×n, B n×m, row-major Float64Arrays) by Gaussian elimination with partial pivoting.
function solve(A, B, n, m) {
  A = Float64Array.from(A); B = Float64Array.from(B);
  for (let c = 0; c < n; c++) {
    let p = c, best = Math.abs(A[c * n + c]);
    for (let r = c + 1; r < n; r++) { const v = Math.abs(A[r * n + c]); if (v > best) { best = v; p = r; } }
    if (best < 1e-12) { A[c * n + c] += 1e-9; p = c; }  // repeated markers: a tiny ridge
    if (p !== c) {
      for (let k = 0; k < n; k++) { const t = A[c * n + k]; A[c * n + k] = A[p * n + k]; A[p * n + k] = t; }
      for (let k = 0; k < m; k++) { const t = B[c * m + k]; B[c * m + k] = B[p * m + k]; B[p * m + k] = t; }
    }
    const d = A[c * n + c];
    for (let r = c + 1; r < n; r++) {
      const f = A[r * n + c] / d;
      if (f === 0) continue;
      for (let k = c; k < n; k++) A[r * n + k] -= f * A[c * n + k];
      for (let k = 0; k < m; k++) B[r * m + k] -= f * B[c * m + k];
    }
  }
  for (let c = n - 1; c >= 0; c--) {
    const d = A[c * n + c];
    for (let k = 0; k < m; k++) {
      let s = B[c * m + k];
      for (let j = c + 1; j < n; j++) s -= A[c * n + j] * B[j * m + k];
      B[c * m + k] = s / d;
    }
  }
  return B;
}

export class BackProjection {
  // markers: [[x, y], ...] (K); values: Float32Array (K, D) — the keyframes' rotation matrices (K, J, 9)
  constructor(markers, values, D) {
    const K = markers.length, n = K + 3;
    this.K = K; this.D = D; this.markers = markers.map((p) => [p[0], p[1]]);
    const A = new Float64Array(n * n), B = new Float64Array(n * D);
    for (let i = 0; i < K; i++) {
      for (let j = 0; j < K; j++) A[i * n + j] = Math.hypot(markers[i][0] - markers[j][0], markers[i][1] - markers[j][1]);
      const poly = [1, markers[i][0], markers[i][1]];
      for (let c = 0; c < 3; c++) { A[i * n + K + c] = poly[c]; A[(K + c) * n + i] = poly[c]; }
      for (let d = 0; d < D; d++) B[i * D + d] = values[i * D + d];
    }
    this.W = solve(A, B, n, D);
    this.phi = new Float64Array(n);
  }

  // The raw RBF outputs at (x, y) into out (Float64Array D).
  raw(x, y, out) {
    const { K, D, W, phi } = this;
    for (let i = 0; i < K; i++) phi[i] = Math.hypot(x - this.markers[i][0], y - this.markers[i][1]);
    phi[K] = 1; phi[K + 1] = x; phi[K + 2] = y;
    out.fill(0);
    for (let i = 0; i < K + 3; i++) {
      const w = phi[i], row = i * D;
      for (let d = 0; d < D; d++) out[d] += w * W[row + d];
    }
    return out;
  }
}

// The rotation nearest to the 3×3 matrix m[o..o+9) (row-major), in place: X <- (X + X^-T) / 2.
export function nearestRotation(m, o) {
  for (let it = 0; it < 20; it++) {
    const a = m[o], b = m[o + 1], c = m[o + 2], d = m[o + 3], e = m[o + 4], f = m[o + 5], g = m[o + 6], h = m[o + 7], i = m[o + 8];
    const A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    const det = a * A + b * B + c * C;
    if (Math.abs(det) < 1e-12) break;
    // inverse transpose = cofactor matrix / det
    const cof = [A, B, C, -(b * i - c * h), a * i - c * g, -(a * h - b * g), b * f - c * e, -(a * f - c * d), a * e - b * d];
    let change = 0;
    for (let k = 0; k < 9; k++) {
      const v = 0.5 * (m[o + k] + cof[k] / det);
      change += Math.abs(v - m[o + k]);
      m[o + k] = v;
    }
    if (change < 1e-10) break;
  }
}

// World positions (P × 3) of joints then End Sites from local rotation matrices R (J × 9), local
// translations T (J × 3), parents (of joints then End Sites), End Site offsets S (E × 3).
export function forwardKinematics(R, T, parents, J, S, out, world) {
  world = world || new Float64Array(J * 9);
  for (let j = 0; j < J; j++) {
    const p = parents[j], o = j * 9;
    if (p < 0) {
      for (let k = 0; k < 9; k++) world[o + k] = R[o + k];
      out[j * 3] = T[j * 3]; out[j * 3 + 1] = T[j * 3 + 1]; out[j * 3 + 2] = T[j * 3 + 2];
      continue;
    }
    const q = p * 9;
    for (let r = 0; r < 3; r++) {
      for (let c = 0; c < 3; c++) {
        world[o + r * 3 + c] = world[q + r * 3] * R[o + c] + world[q + r * 3 + 1] * R[o + 3 + c] + world[q + r * 3 + 2] * R[o + 6 + c];
      }
      out[j * 3 + r] = out[p * 3 + r] + world[q + r * 3] * T[j * 3] + world[q + r * 3 + 1] * T[j * 3 + 1] + world[q + r * 3 + 2] * T[j * 3 + 2];
    }
  }
  for (let s = 0; s < parents.length - J; s++) {
    const p = parents[J + s], q = p * 9, o = (J + s) * 3;
    for (let r = 0; r < 3; r++) {
      out[o + r] = out[p * 3 + r] + world[q + r * 3] * S[s * 3] + world[q + r * 3 + 1] * S[s * 3 + 1] + world[q + r * 3 + 2] * S[s * 3 + 2];
    }
  }
  return out;
}

// The pose at a point of the plane: back-projection, orthonormalisation, forward kinematics.
export class PosePlane {
  constructor(plane) {
    const { header, arrays } = plane;
    this.header = header;
    this.J = header.joints;
    this.parents = header.parents;
    this.rest = Float64Array.from(arrays.rest);
    this.sites = Float64Array.from(arrays.sites);
    this.keyRot = arrays.key_rotations;
    this.R = new Float64Array(this.J * 9);
    this.world = new Float64Array(this.J * 9);
    this.positions = new Float32Array(header.parents.length * 3);
    this.tmp = new Float64Array(header.parents.length * 3);
  }

  setMarkers(markers) { this.bp = new BackProjection(markers, this.keyRot, this.J * 9); }

  // Keep only the keyframes listed (indices into the current keyframe list).
  keep(rows) {
    const D = this.J * 9, kr = new Float32Array(rows.length * D);
    rows.forEach((r, i) => kr.set(this.keyRot.subarray(r * D, (r + 1) * D), i * D));
    this.keyRot = kr;
  }

  pose(x, y) {
    this.bp.raw(x, y, this.R);
    for (let j = 0; j < this.J; j++) nearestRotation(this.R, j * 9);
    forwardKinematics(this.R, this.rest, this.parents, this.J, this.sites, this.tmp, this.world);
    this.positions.set(this.tmp);
    return this.positions;
  }
}
