// Geometry for make_scenes.mjs: small vector and quaternion helpers, mesh builders (spheres,
// quads, a checkerboard), mesh processing (welding, smooth normals, Loop subdivision,
// meshoptimizer simplification) and a tiny PNG encoder. Pure functions: no files are read or
// written here, and the results are deterministic.

import { deflateSync } from 'node:zlib';
import { MeshoptSimplifier } from 'meshoptimizer';
// ---------------------------------------------------------------------------------------------
// Small vector helpers
// ---------------------------------------------------------------------------------------------
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const scl = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const len = (a) => Math.sqrt(dot(a, a));
export const norm = (a) => scl(a, 1 / len(a));
export const round = (x, d = 6) => {
  const r = Math.round(x * 10 ** d) / 10 ** d;
  return Object.is(r, -0) ? 0 : r;
};
export const roundv = (v, d = 6) => v.map((x) => round(x, d));
export const deg = (x) => (x * Math.PI) / 180;

// Quaternion [x, y, z, w] from a rotation matrix given by its columns.
export function quatFromBasis(cx, cy, cz) {
  const m00 = cx[0], m10 = cx[1], m20 = cx[2];
  const m01 = cy[0], m11 = cy[1], m21 = cy[2];
  const m02 = cz[0], m12 = cz[1], m22 = cz[2];
  const tr = m00 + m11 + m22;
  let q;
  if (tr > 0) {
    const s = Math.sqrt(tr + 1) * 2;
    q = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4];
  } else if (m00 > m11 && m00 > m22) {
    const s = Math.sqrt(1 + m00 - m11 - m22) * 2;
    q = [s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s];
  } else if (m11 > m22) {
    const s = Math.sqrt(1 + m11 - m00 - m22) * 2;
    q = [(m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s];
  } else {
    const s = Math.sqrt(1 + m22 - m00 - m11) * 2;
    q = [(m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s];
  }
  if (q[3] < 0) q = q.map((x) => -x); // keep w >= 0
  const l = Math.hypot(...q);
  return q.map((x) => x / l);
}

// Quaternion rotating by `angle` radians about unit `axis`.
export const quatAxisAngle = (axis, angle) => {
  const s = Math.sin(angle / 2);
  return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(angle / 2)];
};

// Rotate v by unit quaternion q.
export function quatRotate(q, v) {
  const u = [q[0], q[1], q[2]];
  const w = q[3];
  const t = scl(cross(u, v), 2);
  return add(add(v, scl(t, w)), cross(u, t));
}

// Camera basis for a camera at `eye` looking at `target` (glTF camera: -Z forward, +Y up).
export function lookAt(eye, target, worldUp = [0, 1, 0]) {
  const f = norm(sub(target, eye));
  const z = scl(f, -1);
  const x = norm(cross(worldUp, z));
  const y = cross(z, x);
  return { x, y, z, f, q: quatFromBasis(x, y, z) };
}

// ---------------------------------------------------------------------------------------------
// Meshes: { positions: [[x,y,z]...], normals: [[x,y,z]...], tris: [[a,b,c]...] }
// ---------------------------------------------------------------------------------------------

// Merge vertices with identical coordinates (to 1e-5) so seams share normals; drops faces that
// collapse. Keeps the first occurrence's order, so the result is deterministic.
export function weld(positions, tris) {
  const map = new Map();
  const out = [];
  const remap = positions.map((p) => {
    const k = p.map((v) => v.toFixed(5)).join(',');
    if (!map.has(k)) {
      map.set(k, out.length);
      out.push(p.slice());
    }
    return map.get(k);
  });
  const t = [];
  for (const [a, b, c] of tris) {
    const A = remap[a], B = remap[b], C = remap[c];
    if (A !== B && B !== C && A !== C) t.push([A, B, C]);
  }
  return { positions: out, tris: t };
}

// Smooth normals: the sum of unnormalised face normals (|n| = 2 * area) around each vertex.
export function smoothNormals(positions, tris) {
  const acc = positions.map(() => [0, 0, 0]);
  for (const [a, b, c] of tris) {
    const n = cross(sub(positions[b], positions[a]), sub(positions[c], positions[a]));
    for (const v of [a, b, c]) acc[v] = add(acc[v], n);
  }
  return acc.map((n) => (len(n) > 0 ? norm(n) : [0, 1, 0]));
}

// Drop unreferenced vertices, renumbering in order of first use.
export function compact(positions, tris) {
  const remap = new Map();
  const out = [];
  const t = tris.map((tri) =>
    tri.map((v) => {
      if (!remap.has(v)) {
        remap.set(v, out.length);
        out.push(positions[v]);
      }
      return remap.get(v);
    })
  );
  return { positions: out, tris: t };
}

export function smoothMesh(positions, tris) {
  return { positions, tris, normals: smoothNormals(positions, tris) };
}

// UV sphere centred at the origin: `segments` around the Y axis, `bands` from pole to pole.
// Triangles: 2 * segments * (bands - 1). Normals are exact (the unit position).
export function uvSphere(radius, segments, bands) {
  const positions = [[0, radius, 0]];
  const normals = [[0, 1, 0]];
  for (let i = 1; i < bands; i++) {
    const theta = (Math.PI * i) / bands;
    for (let j = 0; j < segments; j++) {
      const phi = (2 * Math.PI * j) / segments;
      const n = [Math.sin(theta) * Math.sin(phi), Math.cos(theta), Math.sin(theta) * Math.cos(phi)];
      normals.push(n);
      positions.push(scl(n, radius));
    }
  }
  positions.push([0, -radius, 0]);
  normals.push([0, -1, 0]);
  const bottom = positions.length - 1;
  const ring = (i, j) => 1 + (i - 1) * segments + (((j % segments) + segments) % segments);
  const tris = [];
  for (let j = 0; j < segments; j++) tris.push([0, ring(1, j), ring(1, j + 1)]);
  for (let i = 1; i < bands - 1; i++) {
    for (let j = 0; j < segments; j++) {
      const a = ring(i, j), b = ring(i + 1, j), c = ring(i + 1, j + 1), d = ring(i, j + 1);
      tris.push([a, b, c], [a, c, d]);
    }
  }
  for (let j = 0; j < segments; j++) tris.push([bottom, ring(bands - 1, j + 1), ring(bands - 1, j)]);
  return { positions, normals, tris };
}

// Axis-aligned rectangle in the local XZ plane at y = 0, facing +Y, centred at the origin.
export function quadXZ(sx, sz) {
  const x = sx / 2, z = sz / 2;
  return {
    positions: [[-x, 0, -z], [-x, 0, z], [x, 0, z], [x, 0, -z]],
    normals: [[0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]],
    tris: [[0, 1, 2], [0, 2, 3]],
  };
}

// Rectangle in the local XY plane, facing +Z, bottom edge at y = 0, centred on x = 0.
export function quadXY(sx, sy) {
  const x = sx / 2;
  return {
    positions: [[-x, 0, 0], [x, 0, 0], [x, sy, 0], [-x, sy, 0]],
    normals: [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]],
    tris: [[0, 1, 2], [0, 2, 3]],
  };
}

// UV sphere with texture coordinates: (segments + 1) x (bands + 1) vertices, the seam and the
// poles repeated so that u runs 0..1 around (from +Z towards +X) and v 0..1 from the top pole.
export function uvSphereTextured(radius, segments, bands) {
  const positions = [], normals = [], uvs = [], tris = [];
  for (let i = 0; i <= bands; i++) {
    const theta = (Math.PI * i) / bands;
    for (let j = 0; j <= segments; j++) {
      const phi = (2 * Math.PI * j) / segments;
      const n = [Math.sin(theta) * Math.sin(phi), Math.cos(theta), Math.sin(theta) * Math.cos(phi)];
      normals.push(n);
      positions.push(scl(n, radius));
      uvs.push([j / segments, i / bands]);
    }
  }
  const v = (i, j) => i * (segments + 1) + j;
  for (let i = 0; i < bands; i++) {
    for (let j = 0; j < segments; j++) {
      if (i > 0) tris.push([v(i, j), v(i + 1, j), v(i, j + 1)]);
      if (i < bands - 1) tris.push([v(i, j + 1), v(i + 1, j), v(i + 1, j + 1)]);
    }
  }
  return { positions, normals, uvs, tris };
}

// An 8-bit RGB PNG of w x h texels, texel(x, y) -> [r, g, b] (0..255), row 0 at the top.
export const CRC_TABLE = Array.from({ length: 256 }, (_, n) => {
  let c = n;
  for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
export function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}
export function png(w, h, texel) {
  const raw = Buffer.alloc(h * (1 + 3 * w));
  for (let y = 0; y < h; y++) {
    raw[y * (1 + 3 * w)] = 0;
    for (let x = 0; x < w; x++) raw.set(texel(x, y), y * (1 + 3 * w) + 1 + 3 * x);
  }
  const chunk = (type, body) => {
    const len = Buffer.alloc(4), crc = Buffer.alloc(4);
    len.writeUInt32BE(body.length);
    const tb = Buffer.concat([Buffer.from(type, 'latin1'), body]);
    crc.writeUInt32BE(crc32(tb));
    return Buffer.concat([len, tb, crc]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(w, 0);
  ihdr.writeUInt32BE(h, 4);
  ihdr.set([8, 2, 0, 0, 0], 8);
  return Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr),
    chunk('IDAT', deflateSync(raw, { level: 9 })), chunk('IEND', Buffer.alloc(0))]);
}

// Checkerboard of n x n separate squares of side `cell` in the XZ plane, centred at the origin.
// Returns two meshes: squares where (i + j) is even, and where it is odd.
export function checker(n, cell) {
  const parts = [{ positions: [], normals: [], tris: [] }, { positions: [], normals: [], tris: [] }];
  const h = (n * cell) / 2;
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      const m = parts[(i + j) % 2];
      const x0 = -h + i * cell, x1 = x0 + cell, z0 = -h + j * cell, z1 = z0 + cell;
      const b = m.positions.length;
      m.positions.push([x0, 0, z0], [x0, 0, z1], [x1, 0, z1], [x1, 0, z0]);
      m.normals.push([0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]);
      m.tris.push([b, b + 1, b + 2], [b, b + 2, b + 3]);
    }
  }
  return parts;
}

// Loop subdivision (1 -> 4 triangles) with the usual crease rule on open boundaries.
export function loopSubdivide(positions, tris) {
  const edgeKey = (a, b) => (a < b ? `${a}_${b}` : `${b}_${a}`);
  const edges = new Map(); // key -> { a, b, opp: [vertices opposite], mid }
  const order = [];
  for (const t of tris) {
    for (let k = 0; k < 3; k++) {
      const a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      const key = edgeKey(a, b);
      if (!edges.has(key)) {
        edges.set(key, { a, b, opp: [] });
        order.push(key);
      }
      edges.get(key).opp.push(c);
    }
  }
  const nv = positions.length;
  const ring = positions.map(() => []);
  const boundaryNbrs = positions.map(() => []);
  for (const key of order) {
    const e = edges.get(key);
    ring[e.a].push(e.b);
    ring[e.b].push(e.a);
    if (e.opp.length === 1) {
      boundaryNbrs[e.a].push(e.b);
      boundaryNbrs[e.b].push(e.a);
    }
  }
  // Even (old) vertices.
  const out = positions.map((p, v) => {
    if (boundaryNbrs[v].length > 0) {
      if (boundaryNbrs[v].length !== 2) return p.slice(); // corner / non-manifold: keep
      const [q, r] = boundaryNbrs[v];
      return add(scl(p, 0.75), scl(add(positions[q], positions[r]), 0.125));
    }
    const n = ring[v].length;
    const beta = n === 3 ? 3 / 16 : 3 / (8 * n);
    let s = [0, 0, 0];
    for (const q of ring[v]) s = add(s, positions[q]);
    return add(scl(p, 1 - n * beta), scl(s, beta));
  });
  // Odd (edge) vertices.
  for (const key of order) {
    const e = edges.get(key);
    const pa = positions[e.a], pb = positions[e.b];
    let p;
    if (e.opp.length === 2) {
      p = add(scl(add(pa, pb), 3 / 8), scl(add(positions[e.opp[0]], positions[e.opp[1]]), 1 / 8));
    } else {
      p = scl(add(pa, pb), 0.5);
    }
    e.mid = out.length;
    out.push(p);
  }
  const t2 = [];
  for (const [a, b, c] of tris) {
    const ab = edges.get(edgeKey(a, b)).mid, bc = edges.get(edgeKey(b, c)).mid, ca = edges.get(edgeKey(c, a)).mid;
    t2.push([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]);
  }
  if (out.length !== nv + order.length) throw new Error('loop subdivision bookkeeping');
  return { positions: out, tris: t2 };
}

// meshoptimizer simplification to as close to `targetFaces` as the simplifier gets: tries a
// range of index-count targets and keeps the closest result (ties: the first found).
export function simplifyTo(positions, tris, targetFaces, flags = []) {
  const idx = new Uint32Array(tris.flat());
  const pos = new Float32Array(positions.flat());
  let best = null;
  for (let t = targetFaces - 40; t <= targetFaces + 40; t++) {
    const [res] = MeshoptSimplifier.simplify(idx, pos, 3, t * 3, 1.0, flags);
    const faces = res.length / 3;
    if (best === null || Math.abs(faces - targetFaces) < Math.abs(best.length / 3 - targetFaces)) best = res;
    if (faces === targetFaces) break;
  }
  const t = [];
  for (let i = 0; i < best.length; i += 3) t.push([best[i], best[i + 1], best[i + 2]]);
  return compact(positions, t);
}

export function bboxOf(points) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const p of points) for (let i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); }
  return { lo, hi };
}

export function signedVolume(positions, tris) {
  let v = 0;
  for (const [a, b, c] of tris) v += dot(positions[a], cross(positions[b], positions[c])) / 6;
  return v;
}
