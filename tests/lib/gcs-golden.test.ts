// The GCS model's outputs pinned by a digest (tests/lib/gcs-golden.json), for every criterion and
// mode on our human and the shared characters (../shared/models): the output mesh, its sections,
// blends and centres, and the deformed vertices over a few frames of each clip, bit for bit. Taken
// before the build was split by job (weights builder, paper builder, per-frame kernels): a change
// of any output is a change of the method and rewrites it on purpose (GCS_WRITE_GCS_GOLDEN=1).
import { beforeAll, describe, expect, test } from 'vitest';
import { createHash } from 'node:crypto';
import { readFileSync, writeFileSync } from 'node:fs';
import { basename, dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import type * as THREE from 'three';
import { initGcsSkin, type GcsSkin, type GcsDeformer, type GcsOptions } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { createHuman } from '../../web/lib/human/index.js';
import { sampleClip } from '../../packages/cli/src/gltf-node.js';
import { identitySkin } from '../../web/lib/measure.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const GOLDEN = join(dirname(fileURLToPath(import.meta.url)), 'gcs-golden.json');
const FRAMES_PER_CLIP = 2;
/** Every criterion and mode, at the default level of detail and at the coarsest and a finer one. */
const SETTINGS: GcsOptions[] = [
  { criterion: 'weights' },
  { criterion: 'weights', smooth: false },
  { criterion: 'weights', centres: true },
  { criterion: 'weights', smooth: false, centres: true, sections: 3 },
  { criterion: 'weights', sections: 12 },
  { criterion: 'y' },
  { criterion: 'y', smooth: true, twistSpread: true, influenceWidth: 0.5 },
  { criterion: 'axial', sections: 9 },
  { criterion: 'axial', smooth: true },
];

type Bytes = ArrayLike<number> & { buffer: ArrayBufferLike; byteOffset: number; byteLength: number };

function digest(d: GcsDeformer, frames: Float32Array[]): string {
  const h = createHash('sha256');
  const bytes = (a: Bytes | null) => (a ? h.update(new Uint8Array(a.buffer, a.byteOffset, a.byteLength)) : h.update('-'));
  bytes(d.indices);
  bytes(d.sourceVertex);
  bytes(d.sectionOfVertex());
  h.update(JSON.stringify(d.sections()));
  bytes(d.blendOther());
  bytes(d.blendFactor());
  bytes(d.blendThird());
  bytes(d.blendThirdFactor());
  bytes(d.sectionInfluences());
  bytes(d.sectionCentres());
  for (const skin of [identitySkin(d.jointCount), ...frames]) {
    d.deform(skin);
    bytes(d.positions);
    bytes(d.normals);
    bytes(d.sectionMatrices());
  }
  bytes(Float32Array.of(d.sectionCount, d.partCount, d.adjustedShare, d.adjustedSections));
  return h.digest('hex');
}

describe('GCS: the same outputs as the pinned build', () => {
  test('human and shared characters, every criterion and mode: meshes, sections and deformed vertices bit for bit', async () => {
    const human = createHuman();
    const characters: { name: string; meshes: THREE.SkinnedMesh[]; clips: THREE.AnimationClip[] }[] = [
      { name: 'human', meshes: [human.mesh], clips: human.clips },
    ];
    for (const file of sharedModels().files) {
      const model = await loadGlb(file);
      characters.push({ name: basename(file, '.glb'), meshes: model.skinnedMeshes, clips: model.clips });
    }
    const found: Record<string, string> = {};
    for (const ch of characters)
      for (const mesh of ch.meshes) {
        const rig = gcs.createRig(rigInputFromSkinnedMesh(mesh));
        const frames = ch.clips.flatMap((clip) => sampleClip(mesh, clip, FRAMES_PER_CLIP));
        for (const settings of SETTINGS) {
          const d = rig.buildGcs(settings);
          found[`${ch.name}${ch.meshes.length > 1 ? ` / ${mesh.name}` : ''} ${JSON.stringify(settings)}`] = digest(d, frames);
          d.dispose();
        }
        rig.dispose();
      }
    if (process.env.GCS_WRITE_GCS_GOLDEN) writeFileSync(GOLDEN, `${JSON.stringify(found, null, 2)}\n`);
    const golden = JSON.parse(readFileSync(GOLDEN, 'utf8')) as Record<string, string>;
    const compared = Object.keys(found).filter((k) => k in golden);
    console.log(`gcs golden: ${compared.length} of ${Object.keys(found).length} builds compared`);
    expect(compared.length).toBeGreaterThanOrEqual(SETTINGS.length); // at least the human
    for (const k of compared) expect(found[k], k).toBe(golden[k]);
  });
});
