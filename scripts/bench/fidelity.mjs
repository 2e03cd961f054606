// Geometry measurements for scripts/metrics.mjs (the human-specific ones; the fidelity figures are
// FidelityProbe's, web/lib/measure.ts): posing named bones, plane cross-sections of a limb,
// thickness across a bent joint and under twist, closed-mesh volume.
import * as THREE from 'three';

const norm = (name) => name.toLowerCase().replace(/[^a-z0-9]/g, '');

/** The bone whose name ends with `suffix` (case and punctuation ignored; e.g. mixamorig:LeftLeg). */
export function findBone(bones, suffix) {
  const s = norm(suffix);
  return bones.findIndex((b) => norm(b.name).endsWith(s));
}

/** Rotates bone `index` about the world axis through its joint by `angle` (on top of its current pose). */
export function rotateBoneWorld(bones, index, worldAxis, angle) {
  const bone = bones[index];
  const parentQ = new THREE.Quaternion();
  if (bone.parent) bone.parent.getWorldQuaternion(parentQ);
  const local = worldAxis.clone().applyQuaternion(parentQ.invert()).normalize();
  bone.quaternion.premultiply(new THREE.Quaternion().setFromAxisAngle(local, angle));
}

export function worldPos(bone) {
  return bone.getWorldPosition(new THREE.Vector3());
}

/** Joint of each output vertex of a deformer: via sourceVertex, or the classic model's parts. */
export function outputJoints(deformer, rigDominant) {
  const out = new Int32Array(deformer.vertexCount).fill(-1);
  const source = deformer.sourceVertex;
  if (source) {
    for (let o = 0; o < source.length; o++) if (source[o] < rigDominant.length) out[o] = rigDominant[source[o]];
    return out;
  }
  const parts = deformer.parts;
  if (parts) for (const p of parts) out.fill(p.joint, p.firstVertex, p.firstVertex + p.vertexCount);
  return out;
}

/**
 * Points where the triangles whose three vertices all belong to `joints` cross the plane through
 * `c` with unit normal `n`, within `maxDist` of c.
 */
export function planeSection(positions, indices, vertexJoint, joints, c, n, maxDist, segments = null) {
  const pts = [];
  const P = positions;
  const d = (i) => (P[3 * i] - c.x) * n.x + (P[3 * i + 1] - c.y) * n.y + (P[3 * i + 2] - c.z) * n.z;
  const maxD2 = maxDist * maxDist;
  for (let t = 0; t < indices.length; t += 3) {
    const a = indices[t], b = indices[t + 1], e = indices[t + 2];
    if (!joints.has(vertexJoint[a]) || !joints.has(vertexJoint[b]) || !joints.has(vertexJoint[e])) continue;
    const tri = [a, b, e], ds = [d(a), d(b), d(e)];
    const before = pts.length;
    for (let k = 0; k < 3; k++) {
      const i = tri[k], j = tri[(k + 1) % 3], di = ds[k], dj = ds[(k + 1) % 3];
      if ((di < 0) === (dj < 0)) continue;
      const f = di / (di - dj);
      const x = P[3 * i] + f * (P[3 * j] - P[3 * i]), y = P[3 * i + 1] + f * (P[3 * j + 1] - P[3 * i + 1]), z = P[3 * i + 2] + f * (P[3 * j + 2] - P[3 * i + 2]);
      const dx = x - c.x, dy = y - c.y, dz = z - c.z;
      if (dx * dx + dy * dy + dz * dz <= maxD2) pts.push(new THREE.Vector3(x, y, z));
    }
    if (segments && pts.length - before === 2) segments.push([pts[before], pts[before + 1]]);
  }
  return pts;
}

/**
 * Thickness across a limb in a cross-section: from the centre c along ±e (e in the section
 * plane, perpendicular to `axis`), the distance between the nearest surface crossings on either
 * side. Nearest, so folded-in skin further along the ray does not count. NaN if a side has none.
 */
export function rayThickness(segments, c, e, axis) {
  let pos = Infinity, neg = -Infinity;
  for (const [p, q] of segments) {
    const ap = p.clone().sub(c).dot(axis), aq = q.clone().sub(c).dot(axis);
    if ((ap < 0) === (aq < 0)) continue;
    const x = p.clone().lerp(q, ap / (ap - aq));
    const s = x.sub(c).dot(e);
    if (s >= 0) pos = Math.min(pos, s);
    else neg = Math.max(neg, s);
  }
  return Number.isFinite(pos) && Number.isFinite(neg) ? pos - neg : NaN;
}

/** Extent of points along a unit direction. */
export function extent(points, dir) {
  let lo = Infinity, hi = -Infinity;
  for (const p of points) {
    const s = p.dot(dir);
    if (s < lo) lo = s;
    if (s > hi) hi = s;
  }
  return points.length ? hi - lo : NaN;
}

/** Smallest extent over `k` directions in the plane spanned by unit u, w (the limb's narrowest width). */
export function minWidth(points, u, w, k = 24) {
  let best = Infinity;
  for (let i = 0; i < k; i++) {
    const a = (Math.PI * i) / k;
    best = Math.min(best, extent(points, u.clone().multiplyScalar(Math.cos(a)).addScaledVector(w, Math.sin(a))));
  }
  return points.length ? best : NaN;
}

/** Signed volume of a triangle mesh (sum of origin tetrahedra). */
export function signedVolume(positions, indices) {
  let v = 0;
  const P = positions;
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t], b = 3 * indices[t + 1], c = 3 * indices[t + 2];
    v += P[a] * (P[b + 1] * P[c + 2] - P[b + 2] * P[c + 1]) - P[a + 1] * (P[b] * P[c + 2] - P[b + 2] * P[c]) + P[a + 2] * (P[b] * P[c + 1] - P[b + 1] * P[c]);
  }
  return v / 6;
}

/** Whether the mesh, welded by position, is closed: every edge is shared by exactly two triangles. */
export function isClosed(positions, indices) {
  const id = new Map();
  const weld = new Uint32Array(positions.length / 3);
  for (let v = 0; v < weld.length; v++) {
    const key = `${positions[3 * v]},${positions[3 * v + 1]},${positions[3 * v + 2]}`;
    let w = id.get(key);
    if (w === undefined) id.set(key, (w = id.size));
    weld[v] = w;
  }
  const edges = new Map();
  for (let t = 0; t < indices.length; t += 3)
    for (let k = 0; k < 3; k++) {
      const a = weld[indices[t + k]], b = weld[indices[t + ((k + 1) % 3)]];
      if (a === b) continue;
      const key = a < b ? a * 4294967296 + b : b * 4294967296 + a;
      edges.set(key, (edges.get(key) ?? 0) + 1);
    }
  for (const n of edges.values()) if (n !== 2) return false;
  return edges.size > 0;
}

/** Bind-pose joint centres (mesh space) from the inverse bind matrices. */
export function bindCentres(input) {
  const J = input.parents.length;
  const out = [];
  const m = new THREE.Matrix4();
  for (let j = 0; j < J; j++) {
    m.fromArray(input.inverseBindMatrices, 16 * j).invert();
    out.push(new THREE.Vector3(m.elements[12], m.elements[13], m.elements[14]));
  }
  return out;
}

/** A bind-pose point carried by joint j's skin matrix. */
export function posedCentre(skin, j, c) {
  return c.clone().applyMatrix4(new THREE.Matrix4().fromArray(skin, 16 * j));
}
