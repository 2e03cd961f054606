// The three.js adapter: the geometry's attributes are the wasm views (no copy), they follow
// memory growth, and the output matches three's own skinning at the joints' rigid parts.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { SkinDeformer, rigInputFromSkinnedMesh } from '../../web/lib/three.js';
import { makeTube } from '../helpers/cylinder.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

/** A SkinnedMesh of the analytic tube, bones placed like the tube's joints, moved off the origin. */
function tubeSkinnedMesh() {
  const tube = makeTube({ band: 0.2 });
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(tube.input.positions as Float32Array, 3));
  g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(Array.from(tube.input.joints as Uint32Array), 4));
  g.setAttribute('skinWeight', new THREE.BufferAttribute(tube.input.weights as Float32Array, 4));
  g.setIndex(new THREE.BufferAttribute(tube.input.indices as Uint32Array, 1));
  g.computeVertexNormals();
  const bones = [new THREE.Bone(), new THREE.Bone(), new THREE.Bone()];
  bones[1].position.y = 1;
  bones[2].position.y = 1;
  bones[0].add(bones[1]);
  bones[1].add(bones[2]);
  const mesh = new THREE.SkinnedMesh(g, new THREE.MeshBasicMaterial());
  const group = new THREE.Group();
  group.position.set(3, 0, -2);
  group.rotation.y = 0.7;
  group.add(mesh, bones[0]);
  group.updateMatrixWorld(true);
  mesh.bind(new THREE.Skeleton(bones));
  return { mesh, bones, group, tube };
}

describe('three.js adapter', () => {
  test('reads the rig from a SkinnedMesh', () => {
    const { mesh } = tubeSkinnedMesh();
    const input = rigInputFromSkinnedMesh(mesh);
    expect(Array.from(input.parents)).toEqual([-1, 0, 1]);
    expect(input.positions.length).toBe(mesh.geometry.getAttribute('position').count * 3);
    expect(() => rigInputFromSkinnedMesh(new THREE.Mesh() as unknown as THREE.SkinnedMesh)).toThrow(GcsError);
  });

  test('attributes are views on wasm memory and match three.js skinning', () => {
    const { mesh, bones } = tubeSkinnedMesh();
    for (const method of ['gcs', 'lbs', 'dqs'] as const) {
      // GCS with influence width 0.3: sections farther than 0.3 of a part from the joint are rigid.
      const skin = new SkinDeformer(gcs, mesh, { method, gcs: { influenceWidth: 0.3 } });
      const position = skin.mesh.geometry.getAttribute('position') as THREE.BufferAttribute;
      expect(position.array.buffer).toBe(gcs.memory.buffer);
      bones[1].rotation.z = Math.PI / 2;
      skin.update();
      // Compare with three's CPU skinning in world space. LBS must agree everywhere; GCS and DQS
      // agree where a vertex is rigidly bound (far from the joint).
      const src = skin.deformer.sourceVertex!;
      const v = new THREE.Vector3(), w = new THREE.Vector3();
      let worst = 0;
      for (let o = 0; o < skin.deformer.vertexCount; o++) {
        const i = src[o];
        const y = mesh.geometry.getAttribute('position').getY(i);
        if (method !== 'lbs' && Math.abs(y - 1) < 0.6) continue;
        v.fromBufferAttribute(mesh.geometry.getAttribute("position"), i);
        mesh.applyBoneTransform(i, v).applyMatrix4(mesh.matrixWorld);
        w.fromBufferAttribute(position, o).applyMatrix4(skin.mesh.matrixWorld);
        worst = Math.max(worst, v.distanceTo(w));
      }
      expect(worst, method).toBeLessThan(1e-4);
      bones[1].rotation.z = 0;
      skin.dispose();
    }
  });

  test('views survive wasm memory growth', () => {
    const { mesh, bones } = tubeSkinnedMesh();
    const skin = new SkinDeformer(gcs, mesh, { method: 'gcs' });
    const before = gcs.memory.buffer;
    // Grow the memory by allocating (and keeping) a large block.
    const big = gcs.core.gcs_alloc(64 * 1024 * 1024);
    expect(big).not.toBe(0);
    expect(gcs.memory.buffer).not.toBe(before);
    bones[1].rotation.z = 1;
    skin.update();
    const position = skin.mesh.geometry.getAttribute('position') as THREE.BufferAttribute;
    expect(position.array.buffer).toBe(gcs.memory.buffer);
    expect(position.array.length).toBe(skin.deformer.vertexCount * 3);
    let moved = 0;
    const rest = skin.rig.vertexCount;
    for (let i = 0; i < position.count; i++) if (position.getX(i) < -0.01) moved++;
    expect(moved).toBeGreaterThan(rest / 4); // the bent half swung to -x
    gcs.core.gcs_free(big);
    skin.dispose();
  });

  test('a rebuild that fails leaves the current model in place', () => {
    const { mesh } = tubeSkinnedMesh();
    const skin = new SkinDeformer(gcs, mesh, { method: 'gcs', gcs: { sections: 5 } });
    const sections = skin.deformer.sectionCount;
    expect(() => skin.rebuild('gcs', { gcs: { sections: 1 } })).toThrow(/between 3 and 256/);
    expect(skin.deformer.sectionCount).toBe(sections);
    skin.update();
    skin.rebuild('gcs', { gcs: { sections: 9 } });
    expect(skin.deformer.sectionCount).toBeGreaterThan(sections);
    skin.dispose();
  });
});
