// Generates the paper's test scenes (Fal, Vasconcelos & Delrieux) as glTF 2.0 files in ../../../scenes/.
//
//   cd scripts/scenes/make_scenes && npm ci && node make_scenes.mjs
//
// Every file is a single .gltf with its buffer embedded as a base64 data URI. Conventions shared by
// all scenes (what host/scene/gltf_loader.cpp reads):
//   - world units, +Y up, floors at y = 0;
//   - meshes are indexed TRIANGLES (u16 indices) with float POSITION and NORMAL; winding is
//     counter-clockwise seen from outside; normals are smooth (area-weighted face normals) for
//     curved meshes, exact for analytic spheres, flat for planes;
//   - nodes carry translation / rotation (unit quaternion) / uniform scale only;
//   - materials: pbrMetallicRoughness.baseColorFactor = colour, metallicFactor = reflection
//     coefficient, and the same value again as extras.reflect (which wins when present);
//   - one perspective camera node (glTF: looks down local -Z, +Y up, yfov vertical, aspect 1);
//   - KHR_lights_punctual point lights with intensity 1.0 (the renderer multiplies colour by
//     intensity and applies no physical falloff).
// The output is deterministic: no randomness, no timestamps, fixed iteration orders.
// This file holds the glTF writer and the scenes; the vector and mesh helpers are in geometry.mjs.

import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { MeshoptSimplifier } from 'meshoptimizer';
import {
  sub, add, scl, dot, norm, round, roundv, deg, quatAxisAngle, quatRotate, lookAt, weld, smoothMesh,
  uvSphere, quadXZ, quadXY, uvSphereTextured, png, checker, loopSubdivide, simplifyTo, bboxOf,
  signedVolume,
} from './geometry.mjs';

const require = createRequire(import.meta.url);
const bunny = require('bunny');
const teapot = require('teapot');
const HERE = dirname(fileURLToPath(import.meta.url));
const pkgVersion = (name) => JSON.parse(readFileSync(join(HERE, 'node_modules', name, 'package.json'), 'utf8')).version;
const OUT_DIR = join(HERE, '..', '..', '..', 'scenes');

// ---------------------------------------------------------------------------------------------
// glTF writer
// ---------------------------------------------------------------------------------------------
class Gltf {
  constructor(name, description, source) {
    this.name = name;
    this.description = description;
    this.source = source;
    this.json = {
      asset: { version: '2.0', generator: 'vgpu-rt scripts/scenes/make_scenes/make_scenes.mjs', extras: { description, source } },
      extensionsUsed: ['KHR_lights_punctual'],
      extensions: { KHR_lights_punctual: { lights: [] } },
      scene: 0,
      scenes: [{ name, nodes: [] }],
      nodes: [],
      meshes: [],
      materials: [],
      cameras: [],
      accessors: [],
      bufferViews: [],
      buffers: [],
    };
    this.chunks = [];
    this.byteLength = 0;
    this.faces = 0;
    this.worldPoints = []; // world-space positions of every vertex, for bounds / framing
    this.materialInfo = [];
  }

  addBytes(bytes, target) {
    const pad = (4 - (this.byteLength % 4)) % 4;
    if (pad) { this.chunks.push(new Uint8Array(pad)); this.byteLength += pad; }
    const view = { buffer: 0, byteOffset: this.byteLength, byteLength: bytes.byteLength, target };
    this.chunks.push(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength));
    this.byteLength += bytes.byteLength;
    this.json.bufferViews.push(view);
    return this.json.bufferViews.length - 1;
  }

  addVec3Accessor(vectors, name) {
    const f = new Float32Array(vectors.length * 3);
    vectors.forEach((v, i) => f.set(v, i * 3));
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < f.length; i++) { lo[i % 3] = Math.min(lo[i % 3], f[i]); hi[i % 3] = Math.max(hi[i % 3], f[i]); }
    const view = this.addBytes(f, 34962);
    this.json.accessors.push({ name, bufferView: view, byteOffset: 0, componentType: 5126, count: vectors.length, type: 'VEC3', min: lo, max: hi });
    return this.json.accessors.length - 1;
  }

  addVec2Accessor(vectors, name) {
    const f = new Float32Array(vectors.length * 2);
    vectors.forEach((v, i) => f.set(v, i * 2));
    const view = this.addBytes(f, 34962);
    this.json.accessors.push({ name, bufferView: view, byteOffset: 0, componentType: 5126, count: vectors.length, type: 'VEC2' });
    return this.json.accessors.length - 1;
  }

  // A PNG image in the buffer with its sampler (glTF wrap enums); returns the texture index.
  texture(name, pngBytes, wrapS, wrapT) {
    this.json.images ??= [];
    this.json.samplers ??= [];
    this.json.textures ??= [];
    const view = this.addBytes(new Uint8Array(pngBytes), undefined);
    this.json.images.push({ name, bufferView: view, mimeType: 'image/png' });
    this.json.samplers.push({ magFilter: 9729, minFilter: 9987, wrapS, wrapT });
    this.json.textures.push({ name, source: this.json.images.length - 1, sampler: this.json.samplers.length - 1 });
    (this.textureInfo ??= []).push(name);
    return this.json.textures.length - 1;
  }

  // Float SCALAR, VEC3 or VEC4 elements for an animation sampler (inputs carry min and max, as
  // glTF requires of them).
  addAnimationAccessor(elements, type, name) {
    const n = { SCALAR: 1, VEC3: 3, VEC4: 4 }[type];
    const f = new Float32Array(elements.flat());
    if (f.length !== elements.length * n) throw new Error(`${name}: elements are not ${type}`);
    const view = this.addBytes(f);
    const acc = { name, bufferView: view, byteOffset: 0, componentType: 5126, count: elements.length, type };
    if (type === 'SCALAR') Object.assign(acc, { min: [Math.min(...f)], max: [Math.max(...f)] });
    this.json.accessors.push(acc);
    return this.json.accessors.length - 1;
  }

  // An animation: channels [{ node, path, interpolation, times, values }], one sampler each;
  // values per key (CUBICSPLINE: in-tangent, value, out-tangent per key), as glTF lays them out.
  animation(name, channels, what) {
    const samplers = [], out = [];
    for (const [k, c] of channels.entries()) {
      const tag = `${name} ${this.json.nodes[c.node].name} ${c.path}`;
      samplers.push({
        input: this.addAnimationAccessor(c.times, 'SCALAR', `${tag} times`),
        interpolation: c.interpolation,
        output: this.addAnimationAccessor(c.values, c.path === 'rotation' ? 'VEC4' : 'VEC3', `${tag} values`),
      });
      out.push({ sampler: k, target: { node: c.node, path: c.path } });
    }
    (this.json.animations ??= []).push({ name, channels: out, samplers });
    const end = Math.max(...channels.map((c) => c.times[c.times.length - 1]));
    (this.animationInfo ??= []).push({ name, end, what });
  }

  addIndexAccessor(tris, vertexCount, name) {
    const flat = tris.flat();
    const u16 = vertexCount <= 65535;
    const arr = u16 ? new Uint16Array(flat) : new Uint32Array(flat);
    const view = this.addBytes(arr, 34963);
    let lo = Infinity, hi = -Infinity;
    for (const v of flat) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    this.json.accessors.push({ name, bufferView: view, byteOffset: 0, componentType: u16 ? 5123 : 5125, count: flat.length, type: 'SCALAR', min: [lo], max: [hi] });
    return this.json.accessors.length - 1;
  }

  // reflect: reflection coefficient (0 = none); roughness only matters to other viewers.
  // texture: a texture index for baseColorTexture (multiplied by color), or undefined.
  // glass: { transmission, ior } (KHR_materials_transmission's transmissionFactor and
  // KHR_materials_ior's ior), or undefined for an opaque material.
  material(name, color, reflect, roughness = 0.5, texture = undefined, glass = undefined) {
    const pbr = { baseColorFactor: [...roundv(color, 4), 1], metallicFactor: reflect, roughnessFactor: roughness };
    if (texture !== undefined) pbr.baseColorTexture = { index: texture };
    const m = { name, pbrMetallicRoughness: pbr, extras: { reflect } };
    const info = { name, color: roundv(color, 4), reflect };
    if (glass) {
      m.extensions = {
        KHR_materials_transmission: { transmissionFactor: glass.transmission },
        KHR_materials_ior: { ior: glass.ior },
      };
      for (const e of ['KHR_materials_transmission', 'KHR_materials_ior'])
        if (!this.json.extensionsUsed.includes(e)) this.json.extensionsUsed.push(e);
      Object.assign(info, glass);
    }
    this.json.materials.push(m);
    this.materialInfo.push(info);
    return this.json.materials.length - 1;
  }

  // primitives: [{ mesh: {positions, normals, tris}, material }]
  mesh(name, primitives) {
    const prims = primitives.map(({ mesh, material }, k) => {
      const tag = primitives.length > 1 ? `${name}[${k}]` : name;
      return {
        attributes: {
          POSITION: this.addVec3Accessor(mesh.positions, `${tag} POSITION`),
          NORMAL: this.addVec3Accessor(mesh.normals, `${tag} NORMAL`),
          ...(mesh.uvs ? { TEXCOORD_0: this.addVec2Accessor(mesh.uvs, `${tag} TEXCOORD_0`) } : {}),
        },
        indices: this.addIndexAccessor(mesh.tris, mesh.positions.length, `${tag} indices`),
        material,
        mode: 4,
      };
    });
    this.json.meshes.push({ name, primitives: prims });
    return { index: this.json.meshes.length - 1, primitives };
  }

  node(fields) {
    const n = { ...fields };
    if (n.translation) n.translation = roundv(n.translation);
    if (n.rotation) n.rotation = roundv(n.rotation, 7);
    this.json.nodes.push(n);
    this.json.scenes[0].nodes.push(this.json.nodes.length - 1);
    return this.json.nodes.length - 1;
  }

  // Mesh instance; world transform = T * R * S (uniform s).
  instance(name, meshRef, { t = [0, 0, 0], r = [0, 0, 0, 1], s = 1 } = {}) {
    const node = { name, mesh: meshRef.index };
    if (t.some((x) => x !== 0)) node.translation = t;
    if (r[3] !== 1) node.rotation = r;
    if (s !== 1) node.scale = [s, s, s];
    this.node(node);
    const rr = node.rotation ?? [0, 0, 0, 1];
    const tt = node.translation ?? [0, 0, 0];
    for (const { mesh } of meshRef.primitives) {
      this.faces += mesh.tris.length;
      for (const p of mesh.positions) this.worldPoints.push(add(quatRotate(rr, scl(p, s)), tt));
    }
    return node;
  }

  // Perspective camera at `eye` looking at `target`; yfov chosen so the `frame` points fill
  // `fill` of the half-height/half-width of the 256x256 frame (aspect 1).
  camera(eye, target, framePoints, fill) {
    const { x, y, f, q } = lookAt(eye, target);
    let m = 0;
    for (const p of framePoints) {
      const d = sub(p, eye);
      const depth = dot(d, f);
      m = Math.max(m, Math.abs(dot(d, x)) / depth, Math.abs(dot(d, y)) / depth);
    }
    const yfov = round(2 * Math.atan(m / fill), 4);
    this.json.cameras.push({ name: 'camera', type: 'perspective', perspective: { aspectRatio: 1.0, yfov, znear: 0.05, zfar: 200 } });
    this.node({ name: 'camera', camera: 0, translation: eye, rotation: q });
    this.cameraInfo = { eye: roundv(eye, 4), target: roundv(target, 4), yfov, yfovDeg: round((yfov * 180) / Math.PI, 1) };
  }

  light(name, position, color = [1, 1, 1], intensity = 1.0) {
    const lights = this.json.extensions.KHR_lights_punctual.lights;
    lights.push({ name, type: 'point', color, intensity });
    this.node({ name, translation: position, extensions: { KHR_lights_punctual: { light: lights.length - 1 } } });
    (this.lightInfo ??= []).push({ position: roundv(position, 4), color, intensity });
  }

  write(file) {
    const all = new Uint8Array(this.byteLength + ((4 - (this.byteLength % 4)) % 4));
    let o = 0;
    for (const c of this.chunks) { all.set(c, o); o += c.byteLength; }
    this.json.buffers.push({ byteLength: all.byteLength, uri: 'data:application/octet-stream;base64,' + Buffer.from(all).toString('base64') });
    this.json.asset.extras.faces = this.faces;
    writeFileSync(join(OUT_DIR, file), JSON.stringify(this.json, null, 1) + '\n');
    const b = bboxOf(this.worldPoints);
    const info = { file, description: this.description, source: this.source, faces: this.faces, bounds: { lo: roundv(b.lo, 3), hi: roundv(b.hi, 3) }, camera: this.cameraInfo, lights: this.lightInfo, materials: this.materialInfo };
    if (this.animationInfo) info.animations = this.animationInfo;
    console.log(JSON.stringify(info));
    return info;
  }
}

// Transform mesh positions by uniform scale s then translation t (for framing computations).
const placed = (mesh, s, t, r = [0, 0, 0, 1]) => mesh.positions.map((p) => add(quatRotate(r, scl(p, s)), t));

// ---------------------------------------------------------------------------------------------
// Source meshes
// ---------------------------------------------------------------------------------------------
await MeshoptSimplifier.ready;
mkdirSync(OUT_DIR, { recursive: true });

// Stanford bunny, raw coordinates: x in [-4.96, 4.95], y in [0, 9.65], z in [-3.73, 3.81], +Y up,
// head towards -X. Closed (every edge shared by two faces), genus 0, CCW outward.
const bunnyRaw = weld(bunny.positions, bunny.cells);
if (bunnyRaw.tris.length !== 3674) throw new Error(`bunny: expected 3674 faces, got ${bunnyRaw.tris.length}`);
if (signedVolume(bunnyRaw.positions, bunnyRaw.tris) <= 0) throw new Error('bunny winding is not CCW outward');
const bunnyMesh = smoothMesh(bunnyRaw.positions, bunnyRaw.tris);
const bunnyLowRaw = simplifyTo(bunnyRaw.positions, bunnyRaw.tris, 948);
const bunnyLowMesh = smoothMesh(bunnyLowRaw.positions, bunnyLowRaw.tris);
const BUNNY_SCALE = 0.3; // world: about 3.0 x 2.9 x 2.3, base on y = 0
const bunnyBase = -bunnyMesh.positions.reduce((m, p) => Math.min(m, p[1]), Infinity) * BUNNY_SCALE;

// Utah teapot: 992 faces with seams (duplicated vertices) and open rims; +Y up, centred,
// x in [-16.07, 16.07]. Welded, Loop-subdivided twice (15872 faces) and simplified to ~5030.
const teapotRaw = weld(teapot.positions, teapot.cells);
if (signedVolume(teapotRaw.positions, teapotRaw.tris) <= 0) throw new Error('teapot winding is not CCW outward');
const teapotSub = loopSubdivide(...Object.values(loopSubdivide(teapotRaw.positions, teapotRaw.tris)));
const teapotLow = simplifyTo(teapotSub.positions, teapotSub.tris, 5030, ['RegularizeLight']);
const teapotMesh = smoothMesh(teapotLow.positions, teapotLow.tris);

const summary = [];
const WHITE = [1, 1, 1];
const V = (name) => `npm ${name} ${pkgVersion(name)}`;
const SRC_PROC = 'procedural (this script)';
const SRC_BUNNY = `${V('bunny')}, scaled by 0.3`;
const SRC_BUNNY_LOW = `${V('bunny')}, simplified with ${V('meshoptimizer')} (MeshoptSimplifier.simplify), scaled by 0.3`;
const SRC_TEAPOT = `${V('teapot')}, welded, Loop-subdivided twice (15872 faces) and simplified with ${V('meshoptimizer')} (MeshoptSimplifier.simplify, RegularizeLight), scaled by 0.15`;

// ---------------------------------------------------------------------------------------------
// 1. sphere.gltf — Table 1 "Sphere"
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('sphere', 'Table 1 "Sphere": a UV sphere (radius 1.5, 32 segments x 24 bands, slightly reflective) above a 14 x 14 floor quad', SRC_PROC);
  const mSphere = g.material('red', [0.8, 0.12, 0.08], 0.3, 0.2);
  const mFloor = g.material('floor', [0.75, 0.75, 0.7], 0.0, 0.8);
  const sphere = uvSphere(1.5, 32, 24); // 1472 faces
  const c = [0, 2.0, 0];
  g.instance('sphere', g.mesh('sphere', [{ mesh: sphere, material: mSphere }]), { t: c });
  g.instance('floor', g.mesh('floor', [{ mesh: quadXZ(14, 14), material: mFloor }]));
  g.camera([0, 3.2, 7.5], [0, 1.7, 0], placed(sphere, 1, c), 0.6);
  g.light('light', [-4, 8, 5], WHITE);
  summary.push(g.write('sphere.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 2, 3. bunny.gltf and bunny-low.gltf — Table 1 "Bunny3", Fig. 2
// ---------------------------------------------------------------------------------------------
for (const [file, mesh, what, src] of [
  ['bunny.gltf', bunnyMesh, 'Table 1 "Bunny3" and Fig. 2 (3851-face model): the Stanford bunny alone, all faces, non-reflective', SRC_BUNNY],
  ['bunny-low.gltf', bunnyLowMesh, 'Fig. 2 (948-face model): the Stanford bunny alone, simplified, non-reflective; same camera and light as bunny.gltf', SRC_BUNNY_LOW],
]) {
  const g = new Gltf(file.replace('.gltf', ''), what, src);
  const m = g.material('bunny', [0.85, 0.72, 0.55], 0.0, 0.6);
  const t = [0, bunnyBase, 0];
  g.instance('bunny', g.mesh('bunny', [{ mesh, material: m }]), { s: BUNNY_SCALE, t });
  // Same camera and light for both levels of detail (framed on the full-detail bunny).
  g.camera([2.2, 3.0, 6.5], [0, 1.4, 0], placed(bunnyMesh, BUNNY_SCALE, t), 0.85);
  g.light('light', [4, 7, 6], WHITE);
  summary.push(g.write(file));
}

// ---------------------------------------------------------------------------------------------
// 4. bunny-refl.gltf — Table 1 "BunnyRefl", Fig. 4
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('bunny-refl', 'Table 1 "BunnyRefl" and Fig. 4: the full bunny (turned 30 degrees towards the camera) on a reflective 12 x 12 floor in front of two 7 x 4.5 reflective walls meeting at right angles behind it, for mutual reflections', `${SRC_BUNNY}; floor and walls procedural`);
  const mBunny = g.material('bunny', [0.85, 0.72, 0.55], 0.0, 0.6);
  const mFloor = g.material('floor', [0.55, 0.6, 0.7], 0.5, 0.3);
  const mMirrorL = g.material('mirror-left', [0.75, 0.85, 0.8], 0.7, 0.1);
  const mMirrorR = g.material('mirror-right', [0.85, 0.8, 0.75], 0.6, 0.1);
  const t = [-0.4, bunnyBase, 0];
  const r = quatAxisAngle([0, 1, 0], deg(30)); // turn its head (at -X) a little towards the camera
  g.instance('bunny', g.mesh('bunny', [{ mesh: bunnyMesh, material: mBunny }]), { s: BUNNY_SCALE, t, r });
  g.instance('floor', g.mesh('floor', [{ mesh: quadXZ(12, 12), material: mFloor }]));
  // Two vertical 7 x 4.5 mirrors meeting at right angles behind the bunny, a V open towards
  // the camera; the corner is at (0, 0, -3.5). quadXY faces +Z; yaw it by +-45 degrees about Y.
  const W = 7, H = 4.5, corner = [0, 0, -3.5];
  const wall = quadXY(W, H);
  const left = quatAxisAngle([0, 1, 0], deg(45)); // faces (+x, +z)/sqrt2, spans towards -x
  const right = quatAxisAngle([0, 1, 0], deg(-45)); // faces (-x, +z)/sqrt2, spans towards +x
  const half = W / 2 / Math.SQRT2;
  g.instance('mirror-left', g.mesh('mirror-left', [{ mesh: wall, material: mMirrorL }]), { t: add(corner, [-half, 0, half]), r: left });
  g.instance('mirror-right', g.mesh('mirror-right', [{ mesh: wall, material: mMirrorR }]), { t: add(corner, [half, 0, half]), r: right });
  g.camera([0, 3.2, 8.5], [0, 1.6, -1.0], placed(bunnyMesh, BUNNY_SCALE, t, r).concat([[0, 4.5, -3.5]]), 0.7);
  g.light('light', [3.5, 7, 5], WHITE);
  summary.push(g.write('bunny-refl.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 4b. sphere-alone.gltf, bunny-mirror.gltf — the lighter readings of Table 1's "Sphere" and
// "BunnyRefl" (docs/studies/table1.md): the object alone, and the bunny on a mirror floor only.
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('sphere-alone', 'Table 1 "Sphere" (the reading scripts/docs/table1.py uses): the UV sphere of sphere.gltf alone, no floor; same camera and light', SRC_PROC);
  const mSphere = g.material('red', [0.8, 0.12, 0.08], 0.3, 0.2);
  const sphere = uvSphere(1.5, 32, 24); // 1472 faces
  const c = [0, 2.0, 0];
  g.instance('sphere', g.mesh('sphere', [{ mesh: sphere, material: mSphere }]), { t: c });
  g.camera([0, 3.2, 7.5], [0, 1.7, 0], placed(sphere, 1, c), 0.6);
  g.light('light', [-4, 8, 5], WHITE);
  summary.push(g.write('sphere-alone.gltf'));
}
{
  const g = new Gltf('bunny-mirror', 'Table 1 "BunnyRefl" (the reading scripts/docs/table1.py uses): the full bunny of bunny-refl.gltf on a reflective 6 x 6 floor (about twice its footprint), no walls; same camera and light', `${SRC_BUNNY}; floor procedural`);
  const mBunny = g.material('bunny', [0.85, 0.72, 0.55], 0.0, 0.6);
  const mFloor = g.material('floor', [0.55, 0.6, 0.7], 0.5, 0.3);
  const t = [-0.4, bunnyBase, 0];
  const r = quatAxisAngle([0, 1, 0], deg(30));
  g.instance('bunny', g.mesh('bunny', [{ mesh: bunnyMesh, material: mBunny }]), { s: BUNNY_SCALE, t, r });
  g.instance('floor', g.mesh('floor', [{ mesh: quadXZ(6, 6), material: mFloor }]));
  g.camera([0, 3.2, 8.5], [0, 1.6, -1.0], placed(bunnyMesh, BUNNY_SCALE, t, r), 0.7);
  g.light('light', [3.5, 7, 5], WHITE);
  summary.push(g.write('bunny-mirror.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 5. classic.gltf — Fig. 1 (Whitted-style test scene, 848 faces)
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('classic', 'Fig. 1: the classic (Whitted-style) ray-tracing test scene: a mirror sphere and two coloured reflective spheres (one floating) over an 8 x 8 red/yellow checkerboard of separate quads (16 x 16 units)', SRC_PROC);
  const mRed = g.material('checker-red', [0.8, 0.1, 0.08], 0.0, 0.7);
  const mYellow = g.material('checker-yellow', [0.9, 0.8, 0.15], 0.0, 0.7);
  const mMirror = g.material('mirror-sphere', [0.9, 0.9, 0.92], 0.7, 0.05);
  const mBlue = g.material('blue-sphere', [0.2, 0.35, 0.85], 0.4, 0.2);
  const mGreen = g.material('green-sphere', [0.2, 0.7, 0.3], 0.4, 0.2);
  const [even, odd] = checker(8, 2.0); // 16 x 16 floor, 128 faces
  g.instance('checker', g.mesh('checker', [{ mesh: even, material: mRed }, { mesh: odd, material: mYellow }]));
  const big = uvSphere(1.5, 20, 10); // 360 faces
  const small = uvSphere(0.9, 15, 7); // 180 faces each
  const cBig = [0, 1.55, -1.0], cBlue = [-2.4, 0.95, 1.4], cGreen = [2.2, 1.9, 1.6];
  g.instance('mirror-sphere', g.mesh('mirror-sphere', [{ mesh: big, material: mMirror }]), { t: cBig });
  const smallBlue = g.mesh('blue-sphere', [{ mesh: small, material: mBlue }]);
  const smallGreen = g.mesh('green-sphere', [{ mesh: small, material: mGreen }]);
  g.instance('blue-sphere', smallBlue, { t: cBlue });
  g.instance('green-sphere', smallGreen, { t: cGreen }); // floating, like Whitted's glass ball
  g.camera([0, 2.8, 8.5], [0, 1.3, 0], placed(big, 1, cBig).concat(placed(small, 1, cBlue), placed(small, 1, cGreen)), 0.75);
  g.light('light', [-5, 9, 6], WHITE);
  summary.push(g.write('classic.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 6. teapot.gltf — Fig. 3 (5030 faces, three shading models)
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('teapot', 'Fig. 3 (5030 faces, three shading models): the Utah teapot alone, slightly shiny (roughness 0.25), non-reflective', SRC_TEAPOT);
  const m = g.material('porcelain', [0.75, 0.78, 0.85], 0.0, 0.25);
  const S = 0.15; // world: about 4.8 x 2.4 x 3.0
  const lo = teapotMesh.positions.reduce((a, p) => Math.min(a, p[1]), Infinity);
  const t = [0, Math.ceil(-lo * S * 1e6) / 1e6, 0]; // rests on y = 0 (never below)
  g.instance('teapot', g.mesh('teapot', [{ mesh: teapotMesh, material: m }]), { s: S, t });
  g.camera([2.0, 3.4, 6.5], [0.25, 1.1, 0], placed(teapotMesh, S, t), 0.88);
  g.light('light', [-3, 6, 6], WHITE);
  summary.push(g.write('teapot.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 7. textured.gltf — base-colour textures (issue 25): three textures, one per wrap mode
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('textured', 'base-colour textures, one per wrap mode: a tiled 16 x 16 floor (64 x 64 tile texture repeated 8 x 8: REPEAT, minified into the distance), a globe (128 x 64 texture, REPEAT around, CLAMP_TO_EDGE at the poles), a wall sign (64 x 64, MIRRORED_REPEAT three times across) and an untextured mirror sphere that reflects them', `${SRC_PROC}; textures procedural PNGs in the buffer`);
  const REPEAT = 10497, CLAMP = 33071, MIRROR = 33648;
  const tiles = g.texture('tiles', png(64, 64, (x, y) => {
    if (x % 32 < 2 || y % 32 < 2) return [70, 60, 55]; // grout
    return (x < 32) === (y < 32) ? [225, 210, 180] : [170, 75, 50];
  }), REPEAT, REPEAT);
  const globe = g.texture('globe', png(128, 64, (x, y) => {
    if (x % 16 === 0 || y % 16 === 0) return [250, 250, 250]; // meridians and parallels
    const band = Math.floor(x / 16);
    const hues = [[40, 90, 200], [40, 160, 80], [200, 170, 60], [180, 60, 60], [90, 60, 170], [40, 150, 170], [210, 110, 40], [120, 120, 120]];
    const shade = 0.55 + 0.45 * Math.sin((Math.PI * (y + 0.5)) / 64);
    return hues[band].map((c) => Math.round(c * shade));
  }), REPEAT, CLAMP);
  const sign = g.texture('sign', png(64, 64, (x, y) => {
    const ink = (x >= 12 && x < 22 && y >= 8 && y < 56) || (x >= 12 && x < 50 && y >= 8 && y < 18) || (x >= 12 && x < 40 && y >= 28 && y < 37);
    return ink ? [30, 40, 110] : [235, 230, 215]; // an "F": mirrored copies show which way they face
  }), MIRROR, CLAMP);
  const mFloor = g.material('floor-tiles', WHITE, 0.0, 0.6, tiles);
  const mGlobe = g.material('globe', WHITE, 0.0, 0.3, globe);
  const mSign = g.material('wall-sign', WHITE, 0.0, 0.7, sign);
  const mMirror = g.material('mirror-sphere', [0.9, 0.9, 0.92], 0.6, 0.05);
  const floor = quadXZ(16, 16);
  floor.uvs = [[0, 0], [0, 8], [8, 8], [8, 0]];
  const wall = quadXY(9, 4.5);
  wall.uvs = [[0, 1], [3, 1], [3, 0], [0, 0]];
  const globeMesh = uvSphereTextured(1.4, 32, 16);
  const mirror = uvSphere(1.0, 24, 12);
  const cGlobe = [-1.9, 1.4, 0.2], cMirror = [2.1, 1.0, 1.2], tWall = [0, 0, -4];
  g.instance('floor', g.mesh('floor', [{ mesh: floor, material: mFloor }]));
  g.instance('wall', g.mesh('wall', [{ mesh: wall, material: mSign }]), { t: tWall });
  g.instance('globe', g.mesh('globe', [{ mesh: globeMesh, material: mGlobe }]), { t: cGlobe });
  g.instance('mirror-sphere', g.mesh('mirror-sphere', [{ mesh: mirror, material: mMirror }]), { t: cMirror });
  g.camera([0, 3.0, 9.0], [0, 1.4, 0], placed(globeMesh, 1, cGlobe).concat(placed(mirror, 1, cMirror), placed(wall, 1, tWall)), 0.9);
  g.light('light', [-4, 8, 6], WHITE);
  summary.push(g.write('textured.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 8. hop.gltf — issue 23: a moving scene of the paper's kind (Fig. 1's checkerboard)
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('hop', "Issue 23 (dynamic scenes): the simplified bunny of bunny-low.gltf hops three times across the classic scene's checkerboard while its mirror sphere turns once about a tilted axis; the bounds are the rest pose's (time 0)", `${SRC_BUNNY_LOW.replace('scaled by 0.3', 'scaled by 0.22')}; checkerboard and sphere procedural, as classic.gltf`);
  const mRed = g.material('checker-red', [0.8, 0.1, 0.08], 0.0, 0.7);
  const mYellow = g.material('checker-yellow', [0.9, 0.8, 0.15], 0.0, 0.7);
  const mMirror = g.material('mirror-sphere', [0.9, 0.9, 0.92], 0.7, 0.05);
  const mBunny = g.material('bunny', [0.85, 0.72, 0.55], 0.0, 0.6);
  const [even, odd] = checker(8, 2.0); // 16 x 16 floor, 128 faces
  g.instance('checker', g.mesh('checker', [{ mesh: even, material: mRed }, { mesh: odd, material: mYellow }]));
  const big = uvSphere(1.5, 20, 10); // 360 faces
  const cBig = [0, 1.55, -1.0];
  const axis = norm([Math.sin(deg(30)), Math.cos(deg(30)), 0]); // 30 degrees off +Y
  g.instance('mirror-sphere', g.mesh('mirror-sphere', [{ mesh: big, material: mMirror }]), { t: cBig });
  const sphereNode = g.json.nodes.length - 1;
  // The bunny faces its way (+X: its head, at -X in the model, turned half round about +Y) and
  // leans back on the way up, forward on the way down.
  const S = 0.22, T = 2.0, hops = 3, height = 1.0, x0 = -4.2, x1 = 4.2, z = 1.9;
  const lean = (a) => {
    const yaw = quatAxisAngle([0, 1, 0], Math.PI), pitch = quatAxisAngle([0, 0, 1], deg(a));
    // yaw * pitch: pitch about the model's own Z first.
    const [x1_, y1, z1, w1] = yaw, [x2, y2, z2, w2] = pitch;
    return [w1 * x2 + x1_ * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1_ * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1_ * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1_ * x2 - y1 * y2 - z1 * z2];
  };
  // The lowest point of the scaled bunny in either lean, so that it lands on the floor.
  const lower = Math.min(...[-12, 12].flatMap((a) => placed(bunnyLowMesh, S, [0, 0, 0], lean(a)).map((p) => p[1])));
  g.instance('bunny', g.mesh('bunny', [{ mesh: bunnyLowMesh, material: mBunny }]), { s: S, t: [x0, -lower, z], r: lean(-12) });
  const bunnyNode = g.json.nodes.length - 1;
  // Translation: CUBICSPLINE keys at each take-off, apex and landing. x moves at a constant
  // speed (tangent dx/dt); y follows an exact parabola per half hop (Hermite with end slopes
  // 2h/d and 0 is h(2u - u^2)); a landing's in- and out-tangents differ (the bounce).
  const half = T / hops / 2, vx = (x1 - x0) / T, vy = (2 * height) / half;
  const times = [], values = [];
  for (let k = 0; k <= 2 * hops; k++) {
    const t = k * half, apex = k % 2 === 1;
    const p = [x0 + vx * t, (apex ? height : 0) - lower, z];
    times.push(round(t, 6));
    values.push([vx, apex ? 0 : -vy, 0].map((v) => round(v, 6)), roundv(p), [vx, apex ? 0 : vy, 0].map((v) => round(v, 6)));
  }
  // Rotation: LINEAR (slerp) between leaning back at take-off and forward at landing.
  const rot = times.map((t, k) => roundv(lean(k % 2 === 0 ? -12 : 12), 7));
  // The sphere: a full turn in five keys (slerp between quarter turns).
  const turnTimes = [0, 0.5, 1.0, 1.5, 2.0];
  const turn = turnTimes.map((t) => roundv(quatAxisAngle(axis, (2 * Math.PI * t) / T), 7));
  g.animation('hop', [
    { node: bunnyNode, path: 'translation', interpolation: 'CUBICSPLINE', times, values },
    { node: bunnyNode, path: 'rotation', interpolation: 'LINEAR', times, values: rot },
    { node: sphereNode, path: 'rotation', interpolation: 'LINEAR', times: turnTimes, values: turn },
  ], `${hops} hops of the bunny (translation CUBICSPLINE, rotation LINEAR) and one turn of the mirror sphere (rotation LINEAR) in ${T} s`);
  const ends = [x0, x1].flatMap((x) => placed(bunnyLowMesh, S, [x, height - lower, z]));
  g.camera([0, 3.6, 10.5], [0, 1.0, 0], placed(big, 1, cBig).concat(ends), 0.9);
  g.light('light', [-5, 9, 6], WHITE);
  summary.push(g.write('hop.gltf'));
}

// ---------------------------------------------------------------------------------------------
// 9. glass.gltf — issue 25: glass in the manner of Whitted's 1980 image
// ---------------------------------------------------------------------------------------------
{
  const g = new Gltf('glass', "Issue 25 (glass): Whitted's 1980 image in spirit: a floating glass ball (ior 1.5) and a smaller water-clear one (ior 1.33) in front of a mirror sphere, and a glass bunny (the simplified bunny of bunny-low.gltf, ior 1.5), over the classic scene's red/yellow checkerboard (16 x 16 units), which they refract; every glass mesh is closed (no boundary edges), so each ray that enters one can leave it", `${SRC_BUNNY_LOW.replace('scaled by 0.3', 'scaled by 0.25')}; checkerboard and spheres procedural, as classic.gltf`);
  const mRed = g.material('checker-red', [0.8, 0.1, 0.08], 0.0, 0.7);
  const mYellow = g.material('checker-yellow', [0.9, 0.8, 0.15], 0.0, 0.7);
  const mMirror = g.material('mirror-sphere', [0.9, 0.9, 0.92], 0.7, 0.05);
  const mGlass = g.material('glass-ball', [0.95, 0.97, 1.0], 0.0, 0.0, undefined, { transmission: 0.9, ior: 1.5 });
  const mWater = g.material('water-ball', [0.85, 0.95, 1.0], 0.0, 0.0, undefined, { transmission: 0.95, ior: 1.33 });
  const mBunny = g.material('glass-bunny', [0.8, 0.95, 0.85], 0.0, 0.0, undefined, { transmission: 0.85, ior: 1.5 });
  const [even, odd] = checker(8, 2.0); // 16 x 16 floor, 128 faces
  g.instance('checker', g.mesh('checker', [{ mesh: even, material: mRed }, { mesh: odd, material: mYellow }]));
  const big = uvSphere(1.3, 24, 12); // 528 faces
  const small = uvSphere(0.8, 16, 8); // 224 faces
  const mirror = uvSphere(1.2, 16, 8); // 224 faces
  const cGlass = [-1.5, 2.0, 1.0], cWater = [0.5, 0.8, 3.1], cMirror = [0.2, 1.2, -2.6];
  g.instance('glass-ball', g.mesh('glass-ball', [{ mesh: big, material: mGlass }]), { t: cGlass });
  g.instance('water-ball', g.mesh('water-ball', [{ mesh: small, material: mWater }]), { t: cWater });
  g.instance('mirror-sphere', g.mesh('mirror-sphere', [{ mesh: mirror, material: mMirror }]), { t: cMirror });
  const S = 0.25;
  const lowest = Math.min(...bunnyLowMesh.positions.map((p) => p[1])) * S;
  const r = quatAxisAngle([0, 1, 0], deg(-25));
  const tBunny = [2.7, Math.ceil(-lowest * 1e6) / 1e6, 0.9]; // rests on y = 0 (never below)
  g.instance('glass-bunny', g.mesh('glass-bunny', [{ mesh: bunnyLowMesh, material: mBunny }]), { s: S, t: tBunny, r });
  g.camera([0, 4.4, 9.0], [0.4, 1.0, 0], placed(big, 1, cGlass).concat(placed(small, 1, cWater), placed(mirror, 1, cMirror), placed(bunnyLowMesh, S, tBunny, r)), 0.85);
  g.light('light', [-5, 9, 6], WHITE);
  summary.push(g.write('glass.gltf'));
}

// ---------------------------------------------------------------------------------------------
// scenes/README.md (generated, so its numbers always match the files)
// ---------------------------------------------------------------------------------------------
const fmtv = (v) => `(${v.join(', ')})`;
const lines = [
  '# Scenes',
  '',
  "The test scenes of Fal, Vasconcelos & Delrieux's paper, as glTF 2.0 files (one `.gltf` each, buffer",
  'embedded as a base64 data URI). This file is written by the generator; do not edit it by hand.',
  '',
  'Regenerate (deterministic, byte-identical output):',
  '',
  '```sh',
  'cd scripts/scenes/make_scenes && npm ci && node make_scenes.mjs',
  '```',
  '',
  'Conventions: world units, +Y up, floors at y = 0; indexed TRIANGLES (u16) with float POSITION and',
  'NORMAL, counter-clockwise seen from outside; smooth area-weighted normals on meshes, exact normals on',
  'spheres, flat normals on planes; nodes use translation / rotation / uniform scale only.',
  'Material colour = `pbrMetallicRoughness.baseColorFactor`, reflection coefficient = `metallicFactor`,',
  'repeated as `extras.reflect`. Camera: one perspective node (looks down local -Z, +Y up, vertical',
  '`yfov`, `aspectRatio` 1 for the 256x256 frame). Lights: `KHR_lights_punctual` point lights, white,',
  'intensity 1 (the renderer uses colour x intensity, no physical falloff). Glass: a material\'s',
  '`KHR_materials_transmission.transmissionFactor` and `KHR_materials_ior.ior`, both declared in',
  '`extensionsUsed` (docs/studies/materials.md gives the model).',
  '',
];
for (const s of summary) {
  const cam = s.camera, L = s.lights.map((l) => `${fmtv(l.position)}`).join(', ');
  const glass = (m) => (m.transmission !== undefined ? ` transmission ${m.transmission} ior ${m.ior}` : '');
  const mats = s.materials.map((m) => `${m.name} ${fmtv(m.color)} reflect ${m.reflect}${glass(m)}`).join('; ');
  lines.push(
    `- \`${s.file}\`: ${s.description}; data: ${s.source}; ${s.faces} faces; ` +
      `bounds ${fmtv(s.bounds.lo)} to ${fmtv(s.bounds.hi)}; camera at ${fmtv(cam.eye)} looking at ${fmtv(cam.target)}, ` +
      `yfov ${cam.yfov} rad (${cam.yfovDeg} deg); point light at ${L}; materials: ${mats}` +
      (s.animations ?? []).map((a) => `; animation '${a.name}', 0 to ${a.end} s: ${a.what}`).join('') + '.'
  );
}
lines.push('');
writeFileSync(join(OUT_DIR, 'README.md'), lines.join('\n'));
