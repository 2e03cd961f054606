// Each skeleton posed once a frame (web/lib/three/skeleton-poses.ts, GcsCharacter): skins on the
// same bones with the same bind matrix share one array of skin matrices, written once a frame and
// equal to what each skin would write alone; another bind matrix or other bones get their own; a
// GcsCharacter of two skins on one skeleton deforms them as two separate SkinDeformers would.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { GcsCharacter, SkinDeformer } from '../../web/lib/three.js';
import { SkeletonPoses } from '../../web/lib/three/skeleton-poses.js';
import { writeSkinMatrices } from '../../web/lib/three/skin-matrices.js';
import { makeTube } from '../helpers/cylinder.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** A tube skinned to three bones; `bones` shared when given (each mesh its own Skeleton object, as GLTFLoader makes them). */
function tubeMesh(bones?: THREE.Bone[], bindShift = 0): { mesh: THREE.SkinnedMesh; bones: THREE.Bone[]; root: THREE.Group } {
  const tube = makeTube({ band: 0.2 });
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(tube.input.positions), 3));
  g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(Array.from(tube.input.joints), 4));
  g.setAttribute('skinWeight', new THREE.BufferAttribute(Float32Array.from(tube.input.weights), 4));
  g.setIndex(new THREE.BufferAttribute(Uint32Array.from(tube.input.indices), 1));
  g.computeVertexNormals();
  const root = new THREE.Group();
  if (!bones) {
    bones = [new THREE.Bone(), new THREE.Bone(), new THREE.Bone()];
    bones[1].position.y = 1;
    bones[2].position.y = 1;
    bones[0].add(bones[1]);
    bones[1].add(bones[2]);
    root.add(bones[0]);
  }
  const mesh = new THREE.SkinnedMesh(g, new THREE.MeshBasicMaterial());
  mesh.position.x = bindShift;
  root.add(mesh);
  root.updateMatrixWorld(true);
  mesh.bind(new THREE.Skeleton(bones));
  return { mesh, bones, root };
}

describe('each skeleton posed once a frame', () => {
  test('skins on the same bones share one array, written once a frame, equal to what each writes alone', () => {
    const a = tubeMesh();
    const b = tubeMesh(a.bones);
    a.root.add(b.mesh);
    const c = tubeMesh(a.bones, 0.5); // another bind matrix
    a.root.add(c.mesh);
    const other = tubeMesh(); // other bones
    a.root.updateMatrixWorld(true);
    expect(b.mesh.skeleton).not.toBe(a.mesh.skeleton);
    const poses = new SkeletonPoses();
    const alone = (m: THREE.SkinnedMesh) => { const s = new Float32Array(48); writeSkinMatrices(m, s); return s; };
    for (let frame = 0; frame < 3; frame++) {
      a.bones[1].rotation.z = 0.4 * frame;
      a.root.updateMatrixWorld(true);
      poses.nextFrame();
      const sa = poses.skinOf(a.mesh);
      expect(poses.skinOf(b.mesh)).toBe(sa);
      expect(poses.skinOf(c.mesh)).not.toBe(sa);
      expect(poses.skinOf(other.mesh)).not.toBe(sa);
      for (const m of [a.mesh, b.mesh, c.mesh, other.mesh]) expect(Array.from(poses.skinOf(m))).toEqual(Array.from(alone(m)));
    }
    expect(alone(a.mesh)).not.toEqual(alone(c.mesh)); // the bind matrix matters
  });

  test('a GcsCharacter of two skins on one skeleton deforms them as two SkinDeformers do', () => {
    const a = tubeMesh();
    const b = tubeMesh(a.bones);
    a.root.add(b.mesh);
    const character = new GcsCharacter(gcs, a.root, { method: 'gcs', backend: 'cpu' });
    const a2 = tubeMesh();
    const b2 = tubeMesh(a2.bones);
    a2.root.add(b2.mesh);
    const separate = [new SkinDeformer(gcs, a2.mesh, { method: 'gcs', backend: 'cpu' }), new SkinDeformer(gcs, b2.mesh, { method: 'gcs', backend: 'cpu' })];
    for (const [bones, angle] of [[a.bones, 0.7], [a2.bones, 0.7]] as const) bones[1].rotation.z = angle;
    character.update();
    for (const s of separate) s.update();
    for (let i = 0; i < 2; i++) {
      const mine = character.skins[i].deformer.positions, theirs = separate[i].deformer.positions;
      expect(Array.from(mine)).toEqual(Array.from(theirs));
    }
    character.dispose();
    for (const s of separate) s.dispose();
  });

  // SkeletonPoses keeps boneInverse_j · bindMatrix and multiplies two affine matrices per joint a
  // frame (skinTails); it must give what writeSkinMatrices' three products give.
  test('the kept bind factors give writeSkinMatrices\' matrices; a bone that is not affine takes the full product', () => {
    const a = tubeMesh(undefined, 0.3);
    a.bones[1].scale.set(1.2, 0.8, 1.1);
    const poses = new SkeletonPoses();
    const alone = (m: THREE.SkinnedMesh) => { const s = new Float32Array(48); writeSkinMatrices(m, s); return s; };
    a.bones[2].rotation.x = 0.3;
    a.root.updateMatrixWorld(true);
    poses.nextFrame();
    expect(Array.from(poses.skinOf(a.mesh))).toEqual(Array.from(alone(a.mesh)));
    // A projective world matrix on one bone (not a pose three.js makes, but a matrix it accepts).
    a.bones[2].matrixWorld.elements[3] = 0.25;
    poses.nextFrame();
    const skin = poses.skinOf(a.mesh);
    expect(skin[32 + 3]).not.toBe(0);
    expect(Array.from(skin)).toEqual(Array.from(alone(a.mesh)));
  });

  const shared = sharedModels();
  test.skipIf(!shared.files.length)(`real rigs over their clips: the same matrices as writeSkinMatrices ${shared.reason ?? ''}`, async () => {
    for (const file of shared.files) {
      const model = await loadGlb(file);
      if (!model.clips.length) continue;
      const mixer = new THREE.AnimationMixer(model.scene);
      mixer.clipAction(model.clips[0]).play();
      const poses = new SkeletonPoses();
      let worst = 0;
      for (let f = 0; f < 20; f++) {
        mixer.setTime((model.clips[0].duration * f) / 20);
        model.scene.updateMatrixWorld(true);
        poses.nextFrame();
        for (const m of model.skinnedMeshes) {
          const mine = poses.skinOf(m), theirs = new Float32Array(mine.length);
          writeSkinMatrices(m, theirs);
          for (let k = 0; k < mine.length; k++) worst = Math.max(worst, Math.abs(mine[k] - theirs[k]) / Math.max(1, Math.abs(theirs[k])));
        }
      }
      expect(worst, file).toBeLessThanOrEqual(1e-6);
    }
  });
});
