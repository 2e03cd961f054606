// The three.js adapter: the geometry's attributes are the wasm views (no copy), they follow
// memory growth, and the output matches three's own skinning at the joints' rigid parts.
import { beforeAll, describe, expect, test, vi } from 'vitest';
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
  const mesh = new THREE.SkinnedMesh<THREE.BufferGeometry, THREE.Material | THREE.Material[]>(g, new THREE.MeshBasicMaterial());
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

  test('a SkinnedMesh with joints_1/weights_1 (as GLTFLoader keeps them) is read with 8 influences; a third set warns once', () => {
    const { mesh } = tubeSkinnedMesh();
    const g = mesh.geometry, count = g.getAttribute('position').count;
    const skinWeight = g.getAttribute('skinWeight') as THREE.BufferAttribute;
    // A fifth influence of 0.2 on every third vertex, its first four scaled to sum 1 as
    // GLTFLoader's normalizeSkinWeights leaves them: the reader gives them back 0.8 between them.
    const extraJ = new Uint16Array(4 * count), extraW = new Float32Array(4 * count);
    for (let v = 0; v < count; v += 3) { extraJ[4 * v] = 2; extraW[4 * v] = 0.2; }
    g.setAttribute('joints_1', new THREE.Uint16BufferAttribute(extraJ, 4));
    g.setAttribute('weights_1', new THREE.Float32BufferAttribute(extraW, 4));
    const input = rigInputFromSkinnedMesh(mesh);
    expect(input.influences).toBe(8);
    for (let v = 0; v < count; v++) {
      let sum = 0;
      for (let k = 0; k < 8; k++) sum += input.weights[8 * v + k];
      expect(sum).toBeCloseTo(1, 5);
      for (let k = 0; k < 4; k++) expect(input.weights[8 * v + k]).toBeCloseTo(skinWeight.getComponent(v, k) * (v % 3 === 0 ? 0.8 : 1), 6);
      expect(input.weights[8 * v + 4]).toBe(v % 3 === 0 ? Math.fround(0.2) : 0);
      expect(input.joints[8 * v + 4]).toBe(v % 3 === 0 ? 2 : 0);
    }
    // Without weight in the second set the rig stays at 4 influences (and costs what it did).
    const { mesh: plain } = tubeSkinnedMesh();
    plain.geometry.setAttribute('joints_1', new THREE.Uint16BufferAttribute(new Uint16Array(4 * count), 4));
    plain.geometry.setAttribute('weights_1', new THREE.Float32BufferAttribute(new Float32Array(4 * count), 4));
    expect(rigInputFromSkinnedMesh(plain).influences).toBe(4);
    // A third set (more than 8) is beyond the core: one warning per geometry, the first 8 used.
    g.setAttribute('weights_2', new THREE.Float32BufferAttribute(extraW, 4));
    const warn = vi.spyOn(console, 'warn').mockImplementation(() => {});
    try {
      rigInputFromSkinnedMesh(mesh);
      rigInputFromSkinnedMesh(mesh); // a rebuild reads the same geometry: no second warning
      expect(warn).toHaveBeenCalledTimes(1);
      expect(String(warn.mock.calls[0][0])).toMatch(/more than 8 joint influences per vertex \(joints_2\/weights_2\); only the first 8 are used/);
    } finally {
      warn.mockRestore();
    }
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

  test('defaults: the source\'s material and flags, culling on with bounds that follow the bones; the source stays put', () => {
    const { mesh, bones, group } = tubeSkinnedMesh();
    mesh.name = 'arm';
    mesh.castShadow = true;
    mesh.receiveShadow = true;
    mesh.renderOrder = 2;
    mesh.layers.set(3);
    const skin = new SkinDeformer(gcs, mesh);
    expect(skin.mesh.material).toBe(mesh.material); // the same object, not a copy and not a stand-in
    expect([skin.mesh.name, skin.mesh.castShadow, skin.mesh.receiveShadow, skin.mesh.renderOrder, skin.mesh.layers.mask])
      .toEqual(['arm', true, true, 2, mesh.layers.mask]);
    expect(skin.mesh.frustumCulled).toBe(true);
    // Free placement (the default): not inserted anywhere, carries the source's world transform.
    expect(skin.mesh.parent).toBeNull();
    expect(skin.mesh.matrix.elements).toEqual(mesh.matrixWorld.elements);
    expect(mesh.layers.mask).toBe(1 << 3);
    expect(group.children).toContain(mesh);
    const inside = () => {
      const g = skin.mesh.geometry, p = g.getAttribute('position'), v = new THREE.Vector3();
      let worst = -Infinity;
      for (let i = 0; i < p.count; i++) {
        v.fromBufferAttribute(p, i);
        worst = Math.max(worst, v.distanceTo(g.boundingSphere!.center) - g.boundingSphere!.radius, g.boundingBox!.distanceToPoint(v));
      }
      return worst;
    };
    const before = skin.mesh.geometry.boundingSphere!.center.clone();
    bones[1].rotation.z = 2.5;
    bones[0].position.x = 4;
    skin.update();
    expect(inside()).toBeLessThanOrEqual(0);
    expect(skin.mesh.geometry.boundingSphere!.center.distanceTo(before)).toBeGreaterThan(3); // moved with the bones
    const material = new THREE.MeshNormalMaterial();
    const other = new SkinDeformer(gcs, mesh, { method: 'dqs', material });
    expect(other.mesh.material).toBe(material);
    skin.dispose();
    other.dispose();
    expect(skin.disposed).toBe(true);
    expect(() => skin.update()).toThrow(GcsError);
    expect(material.version).toBe(0); // never disposed nor touched
  });

  test('morph targets: three\'s order (morph, then skin), influences read every update', () => {
    const { mesh, bones } = tubeSkinnedMesh();
    const P = mesh.geometry.getAttribute('position');
    const delta = new Float32Array(P.count * 3);
    for (let i = 0; i < P.count; i++) if (P.getY(i) > 1.4) { delta[3 * i] = 0.3 * P.getX(i); delta[3 * i + 1] = 0.05; }
    mesh.geometry.morphAttributes.position = [new THREE.BufferAttribute(delta, 3)];
    mesh.geometry.morphTargetsRelative = true;
    mesh.updateMorphTargets();
    for (const method of ['lbs', 'gcs'] as const) {
      const skin = new SkinDeformer(gcs, mesh, { method });
      expect(skin.deformer.morphTargetCount).toBe(1);
      bones[1].rotation.z = 0.8;
      for (const w of [0.7, 0]) {
        mesh.morphTargetInfluences![0] = w;
        skin.update();
        const src = skin.deformer.sourceVertex!;
        const position = skin.mesh.geometry.getAttribute('position');
        const v = new THREE.Vector3(), u = new THREE.Vector3();
        let worst = 0;
        for (let o = 0; o < src.length; o++) {
          const i = src[o];
          if (method === 'gcs' && Math.abs(P.getY(i) - 1) < 0.3) continue; // GCS: where bound to one joint
          v.fromBufferAttribute(P, i).addScaledVector(u.fromArray(delta, 3 * i), w);
          mesh.applyBoneTransform(i, v);
          worst = Math.max(worst, v.distanceTo(u.fromBufferAttribute(position, o)));
        }
        expect(worst, `${method} ${w}`).toBeLessThan(1e-5);
      }
      bones[1].rotation.z = 0;
      skin.dispose();
    }
  });

  test('multi-material groups carry over (the deformers keep the triangle order); the classic model falls back to one group', () => {
    const { mesh } = tubeSkinnedMesh();
    const half = Math.floor(mesh.geometry.index!.count / 6) * 3;
    mesh.geometry.addGroup(0, half, 0);
    mesh.geometry.addGroup(half, mesh.geometry.index!.count - half, 1);
    mesh.material = [new THREE.MeshBasicMaterial(), new THREE.MeshBasicMaterial()];
    for (const method of ['gcs', 'lbs', 'dqs', 'classic'] as const) {
      const skin = new SkinDeformer(gcs, mesh, { method });
      expect(skin.mesh.material).toBe(mesh.material);
      const groups = skin.mesh.geometry.groups.map((g) => [g.start, g.count, g.materialIndex]);
      if (method === 'classic') expect(groups).toEqual([[0, Infinity, 0]]);
      else expect(groups, method).toEqual(mesh.geometry.groups.map((g) => [g.start, g.count, g.materialIndex]));
      skin.dispose();
    }
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
