// TriangleGrid (web/lib/surface-distance.ts) against a brute-force search over every triangle: the
// closest-point queries the classic model's attribute transfer and classicOffSurface make. The grid
// stops a search early (after the point's own cell for a point on the surface): it must still find
// the nearest triangle, at the same distance, on the surface, near it and far outside the mesh.
import { describe, expect, test } from 'vitest';
import { createHuman } from '../../web/lib/human/index.js';
import { closestOnTriangle, TriangleGrid, type ClosestPoint } from '../../web/lib/surface-distance.js';

/** A generator of numbers in [0, 1) from a seed (the same points every run). */
function random(seed: number): () => number {
  let s = seed >>> 0;
  return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 2 ** 32);
}

describe('TriangleGrid', () => {
  const geometry = createHuman({ vertices: 3000 }).mesh.geometry;
  const P = geometry.getAttribute('position').array as Float32Array;
  const I = Uint32Array.from(geometry.index!.array);
  const T = I.length / 3;
  const grid = new TriangleGrid();
  grid.build(P, I);
  const hit: ClosestPoint = { triangle: -1, u: 0, v: 0, w: 0 };
  const scratch: ClosestPoint = { triangle: -1, u: 0, v: 0, w: 0 };
  const bruteForce = (x: number, y: number, z: number) => {
    let best = Infinity;
    for (let t = 0; t < T; t++) best = Math.min(best, closestOnTriangle(P, I, t, x, y, z, scratch));
    return best;
  };
  const rand = random(7);
  const points: [string, number, number, number][] = [];
  for (let n = 0; n < 300; n++) {  // on the surface: a random point of a random triangle
    const t = Math.floor(rand() * T), a = rand(), b = rand() * (1 - a);
    const p = (k: number) => (1 - a - b) * P[3 * I[3 * t] + k] + a * P[3 * I[3 * t + 1] + k] + b * P[3 * I[3 * t + 2] + k];
    points.push(['on the surface', p(0), p(1), p(2)]);
    const off = 0.02 * (rand() - 0.5);  // and just off it
    points.push(['near the surface', p(0) + off, p(1) - off, p(2) + 0.5 * off]);
  }
  for (let n = 0; n < 50; n++) points.push(['far outside', 4 * (rand() - 0.5), 4 * rand() - 1, 4 * (rand() - 0.5)]);

  test.each(['on the surface', 'near the surface', 'far outside'])('%s: the distance of the nearest triangle, as a search over every triangle finds it', (kind) => {
    for (const [k, x, y, z] of points) {
      if (k !== kind) continue;
      const d = grid.closest(x, y, z, hit);
      expect(d).toBe(bruteForce(x, y, z));
      expect(closestOnTriangle(P, I, hit.triangle, x, y, z, scratch)).toBe(d);
    }
  });
});
