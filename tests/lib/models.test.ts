// Real characters (../shared/models): each builds, plays every frame of every clip through GCS,
// LBS and DQS with no non-finite value, and GCS at the bind pose returns the input mesh.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { basename } from 'node:path';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { loadGlb, sharedModels, skinMatricesAt } from '../helpers/models.js';

const { files, reason } = sharedModels();
if (reason) console.log(`models.test: ${reason}`);

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

describe.skipIf(files.length === 0)('shared models', () => {
  for (const file of files) {
    test(`${basename(file)}: every clip, every frame, GCS / LBS / DQS`, async () => {
      const model = await loadGlb(file);
      expect(model.skinnedMeshes.length).toBeGreaterThan(0);
      for (const mesh of model.skinnedMeshes) {
        const input = rigInputFromSkinnedMesh(mesh);
        const rig = gcs.createRig(input);
        const deformers = [rig.buildGcs({ sections: 6 }), rig.buildGcs({ sections: 10, smooth: true, twistSpread: true, criterion: 'y' }), rig.buildLbs(), rig.buildDqs()];
        const skin = new Float32Array(rig.jointCount * 16);

        // Bind pose: every S_j is the same transform (the identity, or the mesh node's inverse
        // world transform where the glTF mesh node is transformed), so GCS must return the input
        // mesh carried by it: exactly what LBS gives there.
        mesh.skeleton.pose();
        model.scene.updateMatrixWorld(true);
        mesh.skeleton.bones.forEach((bone, j) => {
          const m = new THREE.Matrix4().multiplyMatrices(bone.matrixWorld, mesh.skeleton.boneInverses[j]);
          m.premultiply(mesh.bindMatrixInverse).multiply(mesh.bindMatrix);
          skin.set(m.elements, 16 * j);
        });
        const lbs = deformers[2];
        lbs.deform(skin);
        const rest = lbs.positions.slice();
        const scale = new THREE.Vector3().setFromMatrixScale(new THREE.Matrix4().fromArray(skin)).x;
        for (const d of deformers.slice(0, 2)) {
          d.deform(skin);
          const src = d.sourceVertex!, pos = d.positions;
          let worst = 0;
          for (let o = 0; o < d.vertexCount; o++)
            for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(pos[3 * o + c] - rest[3 * src[o] + c]));
          expect(worst / (rig.height * scale)).toBeLessThan(1e-4);
        }

        const mixer = new THREE.AnimationMixer(model.scene);
        let frames = 0;
        for (const clip of model.clips) {
          mixer.stopAllAction();
          mixer.clipAction(clip).play();
          const count = Math.max(2, Math.ceil(clip.duration * 30));
          for (let f = 0; f < count; f++) {
            skinMatricesAt(mixer, model.scene, mesh, (clip.duration * f) / count, skin);
            for (const d of deformers) {
              d.deform(skin);
              const pos = d.positions, nrm = d.normals;
              for (let i = 0; i < pos.length; i++) if (!Number.isFinite(pos[i]) || !Number.isFinite(nrm[i])) throw new Error(`${d.kind}: non-finite output in ${clip.name} frame ${f}`);
            }
            frames++;
          }
        }
        expect(frames).toBeGreaterThan(0);
        console.log(`${basename(file)} ${mesh.name}: ${rig.vertexCount} vertices, ${rig.jointCount} joints, ${deformers[0].partCount} parts, ${deformers[0].sectionCount} sections, ${frames} frames`);
        deformers.forEach((d) => d.dispose());
        rig.dispose();
      }
    });
  }
});
