// 8 influences per vertex through the file readers: a copy of CesiumMan (../shared/models, skipped
// with the reason printed when absent) whose weights are spread onto 5–8 joints is written with
// JOINTS_1/WEIGHTS_1 by @gltf-transform (tests/helpers/influences.ts), then
//   - gcs-skin/gltf (loadCharacter) gives rigInput.influences = 8 with the file's eight weights;
//   - `gcs-skin report` counts the vertices with more than 4 influences (table and JSON) and its
//     methods follow the 8-influence reference (DQS p95 ~0);
//   - GcsCharacter (gcs-skin/three, and gcs-skin/webgpu's subclass) on three's own GLTFLoader output
//     (JOINTS_1/WEIGHTS_1 as joints_1/weights_1, its first four renormalised by three) deforms as the
//     8-influence reference computed here (LBS, DQS: float rounding; GCS: within its bounds), and the
//     same character without joints_1/weights_1 — what three's own skinning reads — does not;
//   - a file with 12 influences (JOINTS_2/WEIGHTS_2) keeps each vertex's 8 largest, with a warning.
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, test, vi } from 'vitest';
import * as THREE from 'three';
import { NodeIO } from '@gltf-transform/core';
import { initGcsSkin, type GcsSkin, type RigInput } from '../../web/lib/index.js';
import { GcsCharacter, writeSkinMatrices, type SkinDeformer } from '../../web/lib/three.js';
import { GcsCharacter as WebGpuCharacter } from '../../web/lib/webgpu.js';
import { loadCharacter } from '../../packages/cli/src/gltf.js';
import { parseGlb } from '../../packages/cli/src/gltf-node.js';
import { formatReport, run, type Report } from '../../packages/cli/src/report.js';
import { MODELS_DIR } from '../helpers/models.js';
import { distances, referenceDqs, referenceLbs } from '../helpers/influences.js';
import { eightInfluenceGlb } from '../helpers/influences-glb.js';

const CESIUM = join(MODELS_DIR, 'CesiumMan.glb');
const missing = existsSync(CESIUM) ? '' : `skipped: ${CESIUM} is absent (the shared test models are not on this machine)`;
if (missing) console.log(missing);

/** LBS / DQS against the float64 reference: float32 rounding only; GCS: its bound (tests/lib/influences.test.ts). */
const EXACT = 1e-5, GCS_MAX = 5e-3;

let gcs: GcsSkin;
let dir: string;
let file: string;
let written: { vertices: number; overFour: number };
/** The file's own arrays (read back by gltf-transform, not by three): the reference's input. */
let fileRig: RigInput;

beforeAll(async () => {
  gcs = await initGcsSkin();
  if (missing) return;
  dir = mkdtempSync(join(tmpdir(), 'gcs-influences-'));
  file = join(dir, 'cesium-8.glb');
  written = await eightInfluenceGlb(CESIUM, file);
  const doc = await new NodeIO().read(file);
  const prim = doc.getRoot().listMeshes()[0].listPrimitives()[0];
  const n = prim.getAttribute('POSITION')!.getCount();
  const positions = new Float32Array(3 * n), joints = new Uint32Array(8 * n), weights = new Float32Array(8 * n);
  const p: number[] = [], e: number[] = [];
  for (let v = 0; v < n; v++) {
    positions.set(prim.getAttribute('POSITION')!.getElement(v, p), 3 * v);
    for (let set = 0; set < 2; set++) {
      joints.set(prim.getAttribute(`JOINTS_${set}`)!.getElement(v, e), 8 * v + 4 * set);
      weights.set(prim.getAttribute(`WEIGHTS_${set}`)!.getElement(v, e), 8 * v + 4 * set);
    }
  }
  const J = doc.getRoot().listSkins()[0].listJoints().length;
  fileRig = { positions, indices: [], joints, weights, influences: 8, parents: new Array(J).fill(-1), inverseBindMatrices: [] };
});

afterAll(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

describe.skipIf(!!missing)('8 influences per vertex from a file (CesiumMan, weights spread onto 5–8 joints)', () => {
  test('gcs-skin/gltf reads JOINTS_1/WEIGHTS_1: rigInput.influences = 8, the file\'s eight weights', async () => {
    expect(written.overFour).toBeGreaterThan(0);
    const character = await loadCharacter(file);
    expect(character.warnings).toEqual([]);
    const input = character.meshes[0].rigInput;
    expect(input.influences).toBe(8);
    let worst = 0;
    for (let v = 0; v < written.vertices; v++) {
      const want = new Map<number, number>(), got = new Map<number, number>();
      for (let k = 0; k < 8; k++) {
        if (fileRig.weights[8 * v + k] > 0) want.set(fileRig.joints[8 * v + k], (want.get(fileRig.joints[8 * v + k]) ?? 0) + fileRig.weights[8 * v + k]);
        if (input.weights[8 * v + k] > 0) got.set(input.joints[8 * v + k], (got.get(input.joints[8 * v + k]) ?? 0) + input.weights[8 * v + k]);
      }
      expect([...got.keys()].sort()).toEqual([...want.keys()].sort());
      for (const [j, w] of want) worst = Math.max(worst, Math.abs(got.get(j)! - w));
    }
    expect(worst).toBeLessThan(1e-6);
  });

  test('the report counts vertices with more than 4 influences (table and JSON), its methods on all eight', async () => {
    let stdout = '';
    const spies = [
      vi.spyOn(console, 'log').mockImplementation((...a: unknown[]) => void (stdout += a.join(' ') + '\n')),
      vi.spyOn(process.stderr, 'write').mockImplementation(() => true),
    ];
    let code: number;
    try {
      code = await run([file, '--json', '--frames', '6', '--time-ms', '4']);
    } finally {
      for (const s of spies) s.mockRestore();
    }
    expect(code).toBe(0);
    const r: Report = JSON.parse(stdout);
    const counts = r.meshes[0].counts;
    console.log(`report: ${counts.vertices} vertices, ${counts.influences} influences read, ${counts.moreThan4Influences} with more than 4; ` +
      `DQS p95 from the reference ${r.meshes[0].methods.dqs.fidelity!.dqsP95} %, GCS ${r.meshes[0].methods.gcs.fidelity!.dqsP95} %`);
    expect(counts.influences).toBe(8);
    expect(counts.moreThan4Influences).toBe(written.overFour);
    expect(r.warnings).toEqual([]);
    // The report's DQS reference (gcs-skin/measure) reads all eight too: the core's DQS equals it.
    expect(r.meshes[0].methods.dqs.fidelity!.dqsMax).toBeLessThan(1e-3);
    expect(formatReport(r)).toContain(`influences: 8 per vertex read, ${written.overFour} vertices with more than 4`);
  });

  /** Worst distance over a few clip times between a character's skins and the reference of `method`. */
  async function characterError(Character: typeof GcsCharacter, method: 'lbs' | 'dqs' | 'gcs', dropSecondSet = false): Promise<{ max: number; influences: number }> {
    const { scene, clips } = await parseGlb(readFileSync(file)); // three's GLTFLoader, as a browser gets it
    let source: THREE.SkinnedMesh | undefined;
    scene.traverse((o) => { if ((o as THREE.SkinnedMesh).isSkinnedMesh) source = o as THREE.SkinnedMesh; });
    expect(source!.geometry.getAttribute('joints_1')).toBeDefined();
    if (dropSecondSet) { source!.geometry.deleteAttribute('joints_1'); source!.geometry.deleteAttribute('weights_1'); }
    const character = new Character(gcs, scene, { method });
    const skin: SkinDeformer = character.skins[0];
    const mixer = new THREE.AnimationMixer(scene);
    mixer.clipAction(clips[0]).play();
    let max = 0;
    const S = new Float32Array(16 * source!.skeleton.bones.length);
    for (const t of [0.3, 0.9, 1.6]) {
      mixer.setTime(t);
      character.update();
      writeSkinMatrices(source!, S);
      const want = method === 'lbs' ? referenceLbs(fileRig, S) : referenceDqs(fileRig, S);
      max = Math.max(max, distances(skin.deformer.positions, want, skin.rig.height, skin.deformer.sourceVertex ?? undefined).max);
    }
    const influences = dropSecondSet ? 4 : 8;
    character.dispose();
    return { max, influences };
  }

  test('GcsCharacter on GLTFLoader\'s geometry (joints_1/weights_1) deforms as the 8-influence reference; without them it does not', async () => {
    for (const [entry, Character] of [['three', GcsCharacter], ['webgpu', WebGpuCharacter]] as const) {
      for (const method of ['lbs', 'dqs', 'gcs'] as const) {
        const full = await characterError(Character, method);
        const bound = method === 'gcs' ? GCS_MAX : EXACT;
        console.log(`gcs-skin/${entry} GcsCharacter ${method}: ≤ ${full.max.toExponential(2)} of the height from the 8-influence reference`);
        expect(full.max).toBeLessThan(bound);
        if (entry === 'three') {
          const four = await characterError(Character, method, true);
          console.log(`  … without joints_1/weights_1 (what three's own skinning reads): ${four.max.toExponential(2)}`);
          expect(four.max).toBeGreaterThan(bound);
        }
      }
    }
  });

  test('12 influences (JOINTS_2/WEIGHTS_2): each vertex keeps its 8 largest, renormalised, with a warning', async () => {
    const io = new NodeIO();
    const doc = await io.read(file);
    const prim = doc.getRoot().listMeshes()[0].listPrimitives()[0];
    const n = prim.getAttribute('POSITION')!.getCount();
    // A third set of 4 small weights (0.004 each) on joint 0, the others scaled to keep the sum 1.
    const j2 = new Uint16Array(4 * n), w2 = new Float32Array(4 * n).fill(0.004);
    for (const set of [0, 1]) {
      const a = prim.getAttribute(`WEIGHTS_${set}`)!, w = new Float32Array(4 * n), e: number[] = [];
      for (let v = 0; v < n; v++) w.set(a.getElement(v, e).map((x) => x * 0.984), 4 * v);
      prim.setAttribute(`WEIGHTS_${set}`, doc.createAccessor().setType('VEC4').setArray(w).setBuffer(a.getBuffer()));
    }
    const buffer = prim.getAttribute('WEIGHTS_0')!.getBuffer();
    prim.setAttribute('JOINTS_2', doc.createAccessor().setType('VEC4').setArray(j2).setBuffer(buffer));
    prim.setAttribute('WEIGHTS_2', doc.createAccessor().setType('VEC4').setArray(w2).setBuffer(buffer));
    const twelve = join(dir, 'cesium-12.glb');
    await io.write(twelve, doc);
    const character = await loadCharacter(twelve);
    expect(character.warnings).toHaveLength(1);
    expect(character.warnings[0]).toMatch(
      /^mesh 0 'Cesium_Man' primitive 0 has 12 joint influences per vertex \(JOINTS_0\.\.2, WEIGHTS_0\.\.2\); gcs-skin takes 8: kept the 8 largest of each vertex and renormalised them \([\d,]+ of [\d,]+ vertices lost an influence, the largest lost weight 0\.00400\)$/);
    const input = character.meshes[0].rigInput;
    expect(input.influences).toBe(8);
    for (let v = 0; v < n; v++) {
      let sum = 0;
      for (let k = 0; k < 8; k++) sum += input.weights[8 * v + k];
      expect(Math.abs(sum - 1)).toBeLessThan(1e-5);
    }
  });
});
