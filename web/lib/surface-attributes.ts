// The classic model resamples the skin into contours × rays: its ring vertices are new points with
// no texture coordinates or vertex colours. So that it wears the character's own material, each
// resampled vertex takes the source's attributes at the closest point of the source surface in
// the bind pose (barycentric interpolation on the closest triangle); a carried vertex copies its own
// source vertex (its texture seams stay sharp). Where a resampled triangle straddles a UV seam the
// texture smears across it: the resampled surface has no seam to split along.
import * as THREE from 'three';
import { TriangleGrid, type ClosestPoint } from './surface-distance.js';

/**
 * Sets on `target` every attribute of `source` not in `skip` (uv, uv1…, color, custom ones) for
 * an output mesh whose bind-pose vertices are `restPositions` (xyz, the source's mesh space):
 * output vertex o copies source vertex `sourceOf[o]` when that is ≥ 0, else takes the values at the
 * closest point of the source's triangles. Attributes of more than 4 components are skipped.
 * Returns the names set.
 */
export function transferSurfaceAttributes(source: THREE.BufferGeometry, target: THREE.BufferGeometry,
                                          restPositions: ArrayLike<number>, sourceOf: ArrayLike<number>,
                                          skip: ReadonlySet<string>): string[] {
  const attrs = Object.entries(source.attributes)
    .filter(([name, attr]) => !skip.has(name) && attr.itemSize <= 4)
    .map(([name, attr]) => ({ name, attr }));
  if (!attrs.length) return [];
  const pos = source.getAttribute('position');
  const P = new Float32Array(pos.count * 3);
  for (let i = 0; i < pos.count; i++) { P[3 * i] = pos.getX(i); P[3 * i + 1] = pos.getY(i); P[3 * i + 2] = pos.getZ(i); }
  const index = source.index;
  const T = new Uint32Array(index ? index.count : pos.count);
  for (let i = 0; i < T.length; i++) T[i] = index ? index.getX(i) : i;
  const grid = new TriangleGrid();
  grid.build(P, T, restPositions);
  const n = Math.floor(restPositions.length / 3);
  const outs = attrs.map((a) => ({ ...a, out: new Float32Array(n * a.attr.itemSize) }));
  const hit: ClosestPoint = { triangle: -1, u: 0, v: 0, w: 0 };
  for (let o = 0; o < n; o++) {
    const copy = sourceOf[o] ?? -1;
    if (copy >= 0) {
      for (const { attr, out } of outs) for (let k = 0; k < attr.itemSize; k++) out[o * attr.itemSize + k] = attr.getComponent(copy, k);
      continue;
    }
    grid.closest(restPositions[3 * o], restPositions[3 * o + 1], restPositions[3 * o + 2], hit);
    if (hit.triangle < 0) continue;
    const a = T[3 * hit.triangle], b = T[3 * hit.triangle + 1], c = T[3 * hit.triangle + 2];
    for (const { attr, out } of outs) {
      const size = attr.itemSize;
      for (let k = 0; k < size; k++)
        out[o * size + k] = hit.u * attr.getComponent(a, k) + hit.v * attr.getComponent(b, k) + hit.w * attr.getComponent(c, k);
    }
  }
  for (const { name, out, attr } of outs) target.setAttribute(name, new THREE.BufferAttribute(out, attr.itemSize));
  return outs.map((a) => a.name);
}
