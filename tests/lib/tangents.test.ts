// Tangents in the core pass (gcs_deformer_set_tangents / gcs_deformer_tangents): one deform call
// writes positions, normals and tangents. The spec is what the adapter used to do with a second rig
// and deformer fed the tangents as its normals: the same turn, so the tangent xyz must equal that
// deformer's normals (up to the rig's own rounding of unit rest vectors), on GCS (plain and smooth), LBS and DQS, posed, ×100 and non-uniformly scaled;
// w (handedness) is carried; positions and normals are unchanged by having tangents; bad input is a
// typed error that changes nothing.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type Deformer, type GcsSkin, type Rig, type RigInput } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh, writeSkinMatrices } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { maxDistance, scaledSkin } from '../helpers/skins.js';

let gcs: GcsSkin;
let input: RigInput;
let tangents: Float32Array;
const frames: Float32Array[] = [];

/** Unit tangents perpendicular to the normals (n × a fixed axis), w alternating ±1. */
function tangentsOf(normals: ArrayLike<number>): Float32Array {
  const V = normals.length / 3, out = new Float32Array(4 * V);
  const n = new THREE.Vector3(), t = new THREE.Vector3();
  for (let v = 0; v < V; v++) {
    n.fromArray(normals, 3 * v);
    t.crossVectors(n, Math.abs(n.y) < 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0)).normalize();
    out.set([t.x, t.y, t.z, v % 3 === 0 ? -1 : 1], 4 * v);
  }
  return out;
}

beforeAll(async () => {
  gcs = await initGcsSkin();
  const human = createHuman({ vertices: 4000 });
  input = rigInputFromSkinnedMesh(human.mesh);
  tangents = tangentsOf(input.normals!);
  const mixer = new THREE.AnimationMixer(human.mesh);
  mixer.clipAction(human.clips.find((c) => c.name === 'walk')!).play();
  for (const t of [0.2, 0.6]) {
    mixer.setTime(t);
    human.mesh.updateMatrixWorld(true);
    const skin = new Float32Array(human.mesh.skeleton.bones.length * 16);
    writeSkinMatrices(human.mesh, skin);
    frames.push(skin, scaledSkin(skin, 100, 100, 100), scaledSkin(skin, 1.3, 0.7, 1.1));
  }
});

const BUILDS: [string, (r: Rig) => Deformer][] = [
  ['GCS plain', (r) => r.buildGcs({ smooth: false })],
  ['GCS smooth', (r) => r.buildGcs({ smooth: true })],
  ['LBS', (r) => r.buildLbs()],
  ['DQS', (r) => r.buildDqs()],
];

describe('tangents in the core pass', () => {
  for (const [name, build] of BUILDS) {
    test(`${name}: tangents turn as a deformer fed them as normals; w carried; positions and normals unchanged`, () => {
      const rig = gcs.createRig(input);
      const asNormals = gcs.createRig({ ...input, normals: Float32Array.from({ length: input.normals!.length }, (_, i) => tangents[4 * Math.floor(i / 3) + (i % 3)]) });
      const d = build(rig), plain = build(rig), reference = build(asNormals);
      try {
        expect(d.tangents).toBeNull();
        d.setTangents(tangents);
        const src = d.sourceVertex!;
        expect(Array.from(reference.sourceVertex!)).toEqual(Array.from(src));
        // Before any deform: the rest tangents, in output order.
        for (const o of [0, 7, d.vertexCount - 1]) for (let c = 0; c < 4; c++) expect(d.tangents![4 * o + c]).toBe(tangents[4 * src[o] + c]);
        let worst = 0;
        for (const skin of frames) {
          d.deform(skin);
          plain.deform(skin);
          reference.deform(skin);
          expect(maxDistance(d.positions, plain.positions)).toBe(0);
          expect(maxDistance(d.normals, plain.normals)).toBe(0);
          const out = d.tangents!, xyz = new Float32Array(3 * d.vertexCount);
          for (let o = 0; o < d.vertexCount; o++) {
            xyz.set(out.subarray(4 * o, 4 * o + 3), 3 * o);
            expect(out[4 * o + 3]).toBe(tangents[4 * src[o] + 3]);
          }
          worst = Math.max(worst, maxDistance(xyz, reference.normals));
        }
        console.log(`${name}: tangents vs a deformer fed them as normals, worst ${worst.toExponential(2)} over ${frames.length} frames`);
        expect(worst).toBeLessThan(1e-6);
        // The pose changed them: they are turned, not carried.
        expect(maxDistance(Float32Array.from({ length: 3 * d.vertexCount }, (_, i) => d.tangents![4 * Math.floor(i / 3) + (i % 3)]),
          Float32Array.from({ length: 3 * d.vertexCount }, (_, i) => tangents[4 * src[Math.floor(i / 3)] + (i % 3)]))).toBeGreaterThan(0.1);
      } finally {
        for (const x of [d, plain, reference, rig, asNormals]) x.dispose();
      }
    });
  }

  test('bad tangents are a GcsError and change nothing; null removes them; the classic model takes none', () => {
    const rig = gcs.createRig(input);
    const d = rig.buildGcs();
    const codeOf = (f: () => void) => { try { f(); } catch (e) { return e instanceof GcsError ? e.code : 'not a GcsError'; } return 'no error'; };
    try {
      d.setTangents(tangents);
      const before = Float32Array.from(d.tangents!);
      expect(codeOf(() => d.setTangents(tangents.subarray(4)))).toBe('LENGTH_MISMATCH');
      const nan = Float32Array.from(tangents);
      nan[4 * 11 + 1] = NaN;
      expect(codeOf(() => d.setTangents(nan))).toBe('NON_FINITE');
      expect(Array.from(d.tangents!)).toEqual(Array.from(before));
      d.setTangents(null);
      expect(d.tangents).toBeNull();
      const classic = rig.buildClassic();
      expect(codeOf(() => classic.setTangents(new Float32Array(4 * classic.vertexCount)))).toBe('INVALID_ARGUMENT');
      classic.dispose();
    } finally {
      d.dispose();
      rig.dispose();
    }
  });
});
