// Up to 8 influences per vertex in the core (RigInput.influences, gcs_rig_create's count). The
// characters: CesiumMan and Soldier (../shared/models, skipped with the reason printed when absent)
// with every weight spread onto its joint's parent and child (tests/helpers/influences.ts: 5 to 8
// joints on most vertices). Each method is checked on their clips against an 8-influence reference
// computed here in plain JavaScript (float64): LBS and DQS equal it (float rounding), the classic
// model's carried skin equals the DQS reference, GCS stays as close to the DQS reference as it does
// on 4 influences with its rigid vertices exact. The same check on the rig cut to its first 4
// influences (what a reader of JOINTS_0/WEIGHTS_0 alone deforms) fails: the second set matters.
// Also: the count's validation, and a 4-influence rig's cost unchanged (section table of 2 texels).
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { beforeAll, describe, expect, test } from 'vitest';
import { GcsError, initGcsSkin, MAX_INFLUENCES, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { loadCharacter } from '../../packages/cli/src/gltf.js';
import { MODELS_DIR } from '../helpers/models.js';
import { distances, firstFour, overFour, referenceDqs, referenceLbs, spreadInfluences } from '../helpers/influences.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** LBS / DQS against the float64 reference: float32 rounding only (largest distance, of the height). */
const EXACT = 1e-5;
/**
 * GCS against the DQS reference, p95 and max of the height: the default (smooth nodes) and the
 * stepped level of detail. Measured: the default 0.08–0.10 % p95 and 0.21–0.36 % max (on the
 * files' own 4 influences against their own DQS: 0.03 % p95, 0.13–0.23 % max; a node blending 5–8
 * joints rounds more of its weights to the node grid); stepped
 * 0.6 % p95 and 1.3–2.0 % max, its steps larger than what the second set moves (so the cut to 4
 * is shown failing on the default).
 */
const GCS_BOUNDS = { gcs: { p95: 1.5e-3, max: 5e-3 }, 'gcs-plain': { p95: 1e-2, max: 3e-2 } };

const MODELS = [
  { file: 'CesiumMan.glb', frames: 6 },
  { file: 'Soldier.glb', frames: 4 },
];

function tinyRig(influences: number | undefined, perVertex = influences ?? 4): RigInput {
  // Two triangles, four vertices, two joints; the last influence of each vertex on joint 1.
  const joints: number[] = [], weights: number[] = [];
  for (let v = 0; v < 4; v++) for (let k = 0; k < perVertex; k++) { joints.push(k === perVertex - 1 ? 1 : 0); weights.push(1); }
  return {
    positions: [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0], indices: [0, 1, 2, 2, 1, 3], joints, weights, ...(influences === undefined ? {} : { influences }),
    parents: [-1, 0], inverseBindMatrices: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1],
  };
}

describe('RigInput.influences', () => {
  test('1 … 8 influences per vertex; anything else is a GcsError before anything is copied', () => {
    expect(MAX_INFLUENCES).toBe(8);
    for (const k of [1, 2, 3, 4, 5, 8]) {
      const rig = gcs.createRig(tinyRig(k));
      const lbs = rig.buildLbs();
      // joint 0 = identity, joint 1 = translated by (0, 0, 1): every vertex has 1/k of its weight on joint 1.
      const skin = new Float32Array(32);
      for (let c = 0; c < 4; c++) skin[5 * c] = skin[16 + 5 * c] = 1;
      skin[16 + 14] = 1;
      lbs.deform(skin);
      for (let v = 0; v < 4; v++) expect(lbs.positions[3 * v + 2]).toBeCloseTo(1 / k, 6);
      lbs.dispose();
      rig.dispose();
    }
    const cases: [unknown, string, RegExp][] = [
      [0, 'OUT_OF_RANGE', /^influences must be 1 to 8 per vertex; got 0$/],
      [9, 'OUT_OF_RANGE', /^influences must be 1 to 8 per vertex; got 9$/],
      [4.5, 'INVALID_ARGUMENT', /^influences must be a whole number of influences per vertex \(1 to 8\); got 4\.5$/],
      ['8', 'INVALID_ARGUMENT', /got '8'$/],
      [NaN, 'INVALID_ARGUMENT', /got NaN$/],
    ];
    for (const [influences, code, message] of cases) {
      const input = { ...tinyRig(4), influences } as RigInput;
      const err = (() => { try { gcs.createRig(input); } catch (e) { return e; } return null; })();
      expect(err, String(influences)).toBeInstanceOf(GcsError);
      expect((err as GcsError).code).toBe(code);
      expect((err as GcsError).message).toMatch(message);
    }
    // 8 declared, 4 given per vertex: the lengths disagree.
    expect(() => gcs.createRig({ ...tinyRig(4), influences: 8 })).toThrow(/^joints has 16 ids; 8 per vertex \(influences: 8\) are expected \(32\)$/);
    // The C API checks the count too (before reading or allocating anything).
    const core = gcs.core;
    expect(core.gcs_rig_create(0, 0, 4, 0, 6, 0, 0, 9, 0, 0, 2)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(9); // GCS_ERR_OUT_OF_RANGE
  });

  test('a 4-influence rig keeps its 2-texel section table; a rig of 8 gets 4 texels only where a section blends more than 4 joints', () => {
    const four = gcs.createRig(tinyRig(4));
    const eight = gcs.createRig(tinyRig(8));
    const a = four.buildGcs(), b = eight.buildGcs();
    expect(a.sectionInfluenceSlots).toBe(4);
    expect(a.sectionInfluences()!.length).toBe(8 * a.sectionCount);
    // tinyRig(8) blends 2 joints per vertex: still a 4-slot table.
    expect(b.sectionInfluenceSlots).toBe(4);
    for (const x of [a, b, four, eight]) x.dispose();
  });
});

for (const m of MODELS) {
  const file = join(MODELS_DIR, m.file);
  const missing = existsSync(file) ? '' : `skipped: ${file} is absent (the shared test models are not on this machine)`;
  if (missing) console.log(missing);
  describe.skipIf(!!missing)(`${m.file} with its weights spread onto 5–8 joints`, () => {
    let input: RigInput, cut: RigInput, own: RigInput, frames: Float32Array[], height: number;
    const lbsRef: Float64Array[] = [], dqsRef: Float64Array[] = [];

    beforeAll(async () => {
      const character = await loadCharacter(file);
      const mesh = character.meshes.reduce((a, b) => (a.rigInput.positions.length >= b.rigInput.positions.length ? a : b));
      own = mesh.rigInput;
      input = spreadInfluences(own);
      cut = firstFour(input);
      height = mesh.height;
      const clip = mesh.clips[0];
      frames = Array.from({ length: m.frames }, (_, f) => clip.sample(((f + 0.5) / m.frames) * clip.duration));
      for (const skin of frames) { lbsRef.push(referenceLbs(input, skin)); dqsRef.push(referenceDqs(input, skin)); }
      console.log(`${m.file}: ${overFour(input)} of ${input.positions.length / 3} vertices have more than 4 influences after spreading`);
    });

    /** The worst distance over the frames of a deformer built by `build` on `rig` from `reference`. */
    function measure(rig: RigInput, reference: Float64Array[], build: 'lbs' | 'dqs' | 'gcs' | 'gcs-plain'): { max: number; p95: number; slots: number } {
      const r = gcs.createRig(rig);
      const d = build === 'lbs' ? r.buildLbs() : build === 'dqs' ? r.buildDqs() : r.buildGcs({ smooth: build === 'gcs' });
      let max = 0, p95 = 0;
      frames.forEach((skin, f) => {
        d.deform(skin);
        const e = distances(d.positions, reference[f], height, d.sourceVertex ?? undefined);
        max = Math.max(max, e.max);
        p95 = Math.max(p95, e.p95);
      });
      const slots = 'sectionInfluenceSlots' in d ? (d as { sectionInfluenceSlots: number }).sectionInfluenceSlots : 0;
      d.dispose();
      r.dispose();
      return { max, p95, slots };
    }

    test('LBS and DQS equal the 8-influence reference; cut to 4 they do not', () => {
      expect(overFour(input)).toBeGreaterThan(0.1 * (input.positions.length / 3));
      for (const [method, reference] of [['lbs', lbsRef], ['dqs', dqsRef]] as const) {
        const full = measure(input, reference, method), four = measure(cut, reference, method);
        console.log(`${m.file} ${method}: 8 influences ≤ ${full.max.toExponential(2)} of the height from the reference; first 4 only: ${four.max.toExponential(2)}`);
        expect(full.max).toBeLessThan(EXACT);
        expect(four.max).toBeGreaterThan(100 * EXACT); // the reference would catch a reader of the first set alone
      }
    });

    test('GCS (smooth and plain) follows the 8-influence DQS reference, rigid vertices exact; cut to 4 the default does not', () => {
      const ownRef = frames.map((skin) => referenceDqs(own, skin)), base = measure(own, ownRef, 'gcs');
      console.log(`${m.file} gcs on the file's own 4 influences: from their DQS p95 ${base.p95.toExponential(2)}, max ${base.max.toExponential(2)} of the height`);
      const results = (['gcs', 'gcs-plain'] as const).map((mode) => {
        const full = measure(input, dqsRef, mode), four = measure(cut, dqsRef, mode);
        console.log(`${m.file} ${mode}: from the 8-influence DQS p95 ${full.p95.toExponential(2)}, max ${full.max.toExponential(2)} of the height ` +
          `(table ${full.slots} joints per section); first 4 only: p95 ${four.p95.toExponential(2)}, max ${four.max.toExponential(2)}`);
        return { mode, full, four };
      });
      for (const { mode, full, four } of results) {
        expect(full.slots).toBe(8);
        expect(full.p95).toBeLessThan(GCS_BOUNDS[mode].p95);
        expect(full.max).toBeLessThan(GCS_BOUNDS[mode].max);
        if (mode === 'gcs') expect(four.max).toBeGreaterThan(GCS_BOUNDS[mode].max); // the bound would catch a reader of the first set alone
      }
      // Vertices bound 100 % to one joint move exactly with it.
      const r = gcs.createRig(input), d = r.buildGcs();
      const src = d.sourceVertex!;
      let worst = 0, rigid = 0;
      frames.forEach((skin, f) => {
        d.deform(skin);
        for (let o = 0; o < d.vertexCount; o++) {
          const v = src[o];
          if (!(input.weights[8 * v] >= 0.999)) continue;
          if (f === 0) rigid++;
          worst = Math.max(worst, Math.hypot(d.positions[3 * o] - lbsRef[f][3 * v], d.positions[3 * o + 1] - lbsRef[f][3 * v + 1], d.positions[3 * o + 2] - lbsRef[f][3 * v + 2]) / height);
        }
      });
      d.dispose();
      r.dispose();
      console.log(`${m.file}: ${rigid} rigid vertices, ≤ ${worst.toExponential(2)} of the height from S_j·x`);
      expect(rigid).toBeGreaterThan(0);
      expect(worst).toBeLessThan(EXACT);
    });

    test("the classic model's carried skin equals the 8-influence DQS reference; cut to 4 it does not", () => {
      const worst = (rig: RigInput) => {
        const r = gcs.createRig(rig), d = r.buildClassic();
        const source = d.sourceOfVertex;
        let max = 0, carried = 0;
        frames.forEach((skin, f) => {
          d.deform(skin);
          for (let o = 0; o < d.vertexCount; o++) {
            const v = source[o];
            if (v < 0) continue;
            if (f === 0) carried++;
            max = Math.max(max, Math.hypot(d.positions[3 * o] - dqsRef[f][3 * v], d.positions[3 * o + 1] - dqsRef[f][3 * v + 1], d.positions[3 * o + 2] - dqsRef[f][3 * v + 2]) / height);
          }
        });
        d.dispose();
        r.dispose();
        return { max, carried };
      };
      const full = worst(input), four = worst(cut);
      console.log(`${m.file} classic: ${full.carried} carried vertices ≤ ${full.max.toExponential(2)} of the height from the reference; first 4 only: ${four.max.toExponential(2)}`);
      expect(full.carried).toBeGreaterThan(0);
      expect(full.max).toBeLessThan(EXACT);
      expect(four.max).toBeGreaterThan(100 * EXACT);
    });
  });
}
