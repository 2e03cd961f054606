// The default GCS's nodes in weight space (wasm/src/gcs_build_weights.cpp, buildWeightNodes): each vertex's
// blend of its nodes reproduces its own skin weights. Two-joint vertices blend two nodes on a ray
// from a rigid core; three-joint vertices the three corners of their weight-lattice cell. A wrong
// corner or barycentric factor, or a cell of the wrong triangulation, shows as a weight mismatch;
// corners shared across a cell edge make the result continuous in the weights.
import { beforeAll, describe, expect, test } from 'vitest';
import { initGcsSkin, type GcsDeformer, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { cleanWeights } from '../helpers/clean-weights.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** Section s's blend weights from the joint-level table. */
function nodeWeights(table: Float32Array, slots: number, s: number): Map<number, number> {
  const out = new Map<number, number>();
  for (let k = 0; k < slots; k++) {
    const texels = 2 * slots * s + 8 * (k >> 2);
    const joint = table[texels + (k & 3)];
    if (joint < 0) break;
    out.set(joint, table[texels + 4 + (k & 3)]);
  }
  return out;
}

interface Reproduction { byJoints: Map<number, { vertices: number; worst: number }>; cells: number; nodes: number }

/** The vertices at each rest position: the builder welds them (a UV seam never opens) and reads one's weights. */
function weldedGroups(input: RigInput): Map<string, number[]> {
  const groups = new Map<string, number[]>();
  for (let v = 0; v < input.positions.length / 3; v++) {
    const key = `${input.positions[3 * v]},${input.positions[3 * v + 1]},${input.positions[3 * v + 2]}`;
    const group = groups.get(key);
    if (group) group.push(v);
    else groups.set(key, [v]);
  }
  return groups;
}

/** For every output vertex: |Σ factor · node weights − the weights of a vertex it is welded to|, worst per joint count. */
function reproduce(input: RigInput, d: GcsDeformer): Reproduction {
  const groups = weldedGroups(input);
  const table = d.sectionInfluences()!, slots = d.sectionInfluenceSlots;
  const section = d.sectionOfVertex(), source = d.sourceVertex!;
  const other = d.blendOther()!, f = d.blendFactor()!, third = d.blendThird()!, g = d.blendThirdFactor()!;
  const byJoints = new Map<number, { vertices: number; worst: number }>();
  const cells = new Set<string>();
  for (let o = 0; o < d.vertexCount; o++) {
    const blended = new Map<number, number>();
    const parts: [number, number][] = [[section[o], 1 - f[o] - g[o]], [other[o], f[o]], [third[o], g[o]]];
    for (const [s, factor] of parts)
      for (const [j, w] of nodeWeights(table, slots, s)) blended.set(j, (blended.get(j) ?? 0) + factor * w);
    const v = source[o];
    const welded = groups.get(`${input.positions[3 * v]},${input.positions[3 * v + 1]},${input.positions[3 * v + 2]}`)!;
    let own = cleanWeights(input, v), worst = Infinity;
    for (const u of welded) {
      const w = cleanWeights(input, u);
      let e = 0;
      for (const j of new Set([...w.keys(), ...blended.keys()])) e = Math.max(e, Math.abs((w.get(j) ?? 0) - (blended.get(j) ?? 0)));
      if (e < worst) worst = e, own = w;
    }
    const entry = byJoints.get(own.size) ?? { vertices: 0, worst: 0 };
    entry.vertices++;
    entry.worst = Math.max(entry.worst, worst);
    byJoints.set(own.size, entry);
    if (third[o] !== section[o]) cells.add(`${section[o]},${other[o]},${third[o]}`);
  }
  return { byJoints, cells: cells.size, nodes: d.sectionCount };
}

function check(name: string, input: RigInput): void {
  const rig = gcs.createRig(input);
  const d = rig.buildGcs({});
  const r = reproduce(input, d);
  const summary = [...r.byJoints].sort(([a], [b]) => a - b).map(([n, e]) => `${n} joints: ${e.vertices} vertices, worst ${e.worst.toExponential(1)}`);
  console.log(`${name}: ${r.nodes} nodes, ${r.cells} three-node cells; ${summary.join('; ')}`);
  // One, two and three joints: the blend is exactly the vertex's weights (float rounding only).
  for (const n of [1, 2, 3]) if (r.byJoints.has(n)) expect(r.byJoints.get(n)!.worst).toBeLessThan(2e-6);
  // Four or more: the shape of the small weights is kept to 1/(8Q) = 1/64 of weight at the default.
  for (const [n, e] of r.byJoints) if (n > 3) expect(e.worst).toBeLessThanOrEqual(1 / 64 + 1e-6);
  if ((r.byJoints.get(3)?.vertices ?? 0) > 0) expect(r.cells).toBeGreaterThan(0);
  d.dispose();
  rig.dispose();
}

describe('the default nodes reproduce every vertex\'s skin weights', () => {
  test('our human (1,469 three-joint vertices)', () => {
    const human = createHuman();
    check('human', rigInputFromSkinnedMesh(human.mesh));
  });

  const { files, reason } = sharedModels();
  if (reason) console.log(reason);
  for (const file of files) {
    test(`${file.split('/').pop()}: every skinned mesh`, async () => {
      const model = await loadGlb(file);
      for (const mesh of model.skinnedMeshes) check(`${file.split('/').pop()} ${mesh.name}`, rigInputFromSkinnedMesh(mesh));
    });
  }
});

// A rig keeps what no section count changes (the weld, each welded group's cleaned weights and
// two-joint pair: wasm/src/rig.h): a build on a rig that built other settings first must equal,
// byte for byte, one on a fresh rig.
describe('a rebuild on a used rig equals a build on a fresh rig', () => {
  test('our human: sections 3, 5, 6, 8 and 12, smooth, plain and with centres', () => {
    const input = rigInputFromSkinnedMesh(createHuman().mesh);
    const used = gcs.createRig(input);
    const settings = [3, 5, 6, 8, 12].flatMap((sections) => [{ sections }, { sections, smooth: false }, ...(sections % 3 ? [] : [{ sections, centres: true }])]);
    for (const s of settings) used.buildGcs(s).dispose(); // every setting once: the rig's caches filled
    const tables = (d: GcsDeformer) => [d.indices, d.sourceVertex, d.sectionOfVertex(), d.blendOther(), d.blendFactor(), d.blendThird(),
      d.blendThirdFactor(), d.sectionInfluences(), d.sectionCentres(), d.positions];
    const bytes = (x: ArrayBufferView | null) => (x ? Buffer.from(x.buffer, x.byteOffset, x.byteLength) : Buffer.alloc(0));
    for (const s of settings.reverse()) {
      const fresh = gcs.createRig(input);
      const a = used.buildGcs(s), b = fresh.buildGcs(s);
      expect(a.sectionCount, JSON.stringify(s)).toBe(b.sectionCount);
      const tb = tables(b);
      tables(a).forEach((x, i) => expect(bytes(x).equals(bytes(tb[i])), `${JSON.stringify(s)} table ${i}`).toBe(true));
      a.dispose();
      b.dispose();
      fresh.dispose();
    }
    used.dispose();
  });
});
