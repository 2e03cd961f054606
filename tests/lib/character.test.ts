// GcsCharacter: a whole character driven in place. A programmatic character (a body with uv,
// vertex colours, tangents and a morph target, and a visor on its own skeleton, under
// transformed groups) checked against three.js's own skinning (morph, then skin), for
// placement, materials and flags, moving bounds, raycasts, rebuilds and dispose.
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type ClassicDeformer, type DeformerKind, type GcsSkin } from '../../web/lib/index.js';
import { GcsCharacter, SkinDeformer } from '../../web/lib/three.js';
import { makeTube } from '../helpers/cylinder.js';
import { loadGlb, sharedModels } from '../helpers/models.js';

let gcs: GcsSkin;
beforeAll(async () => {
  gcs = await initGcsSkin();
});

const RADIUS = 0.2;

/** Body: a two-part tube (bones 0-1-2 along y, joint at y = 1) with uv, colours, tangents, one morph. */
function makeBody(): { mesh: THREE.SkinnedMesh; bones: THREE.Bone[] } {
  const tube = makeTube({ band: 0.2, radius: RADIUS, seam: true });
  const g = new THREE.BufferGeometry();
  const P = tube.input.positions as Float32Array;
  const n = P.length / 3;
  g.setAttribute('position', new THREE.BufferAttribute(P, 3));
  g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(Array.from(tube.input.joints as Uint32Array), 4));
  g.setAttribute('skinWeight', new THREE.BufferAttribute(tube.input.weights as Float32Array, 4));
  // The helper's triangles face inwards: turned, so that normals and front faces point out.
  const index = Uint32Array.from(tube.input.indices as Uint32Array);
  for (let t = 0; t < index.length; t += 3) [index[t + 1], index[t + 2]] = [index[t + 2], index[t + 1]];
  g.setIndex(new THREE.BufferAttribute(index, 1));
  const uv = new Float32Array(2 * n), colour = new Uint8Array(4 * n);
  for (let v = 0; v < n; v++) {
    uv[2 * v] = (v % (tube.segments + 1)) / tube.segments;
    uv[2 * v + 1] = tube.along[v] / 2;
    colour.set([v % 256, (7 * v) % 256, 255 - (v % 256), 200], 4 * v);
  }
  g.setAttribute('uv', new THREE.BufferAttribute(uv, 2));
  g.setAttribute('color', new THREE.BufferAttribute(colour, 4, true));
  g.computeVertexNormals();
  g.computeTangents();
  // One morph target (relative, as GLTFLoader gives it): the upper part swells and the tip shifts.
  const delta = new Float32Array(3 * n);
  for (let v = 0; v < n; v++) {
    if (tube.along[v] > 1.3) { delta[3 * v] = 0.5 * P[3 * v]; delta[3 * v + 2] = 0.5 * P[3 * v + 2]; }
    if (tube.along[v] > 1.8) delta[3 * v + 2] += 0.1;
  }
  g.morphAttributes.position = [new THREE.BufferAttribute(delta, 3)];
  g.morphTargetsRelative = true;
  const map = new THREE.DataTexture(new Uint8Array([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255]), 2, 2);
  map.needsUpdate = true;
  const material = new THREE.MeshStandardMaterial({ map, vertexColors: true, roughness: 0.6 });
  const mesh = new THREE.SkinnedMesh(g, material);
  mesh.name = 'body';
  mesh.castShadow = true;
  mesh.receiveShadow = false;
  mesh.renderOrder = 3;
  mesh.layers.enable(2);
  const bones = [new THREE.Bone(), new THREE.Bone(), new THREE.Bone()];
  bones.forEach((b, i) => { b.name = `body${i}`; });
  bones[1].position.y = 1;
  bones[2].position.y = 1;
  bones[0].add(bones[1]);
  bones[1].add(bones[2]);
  return { mesh, bones };
}

/** Visor: a box bound 100 % to the second bone of its own two-bone skeleton. */
function makeVisor(): { mesh: THREE.SkinnedMesh; bones: THREE.Bone[] } {
  const g = new THREE.BoxGeometry(0.3, 0.15, 0.1, 2, 1, 1).translate(0, 2.2, 0.25);
  const n = g.getAttribute('position').count;
  g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(new Array(4 * n).fill(0).map((_, i) => (i % 4 === 0 ? 1 : 0)), 4));
  g.setAttribute('skinWeight', new THREE.Float32BufferAttribute(new Array(4 * n).fill(0).map((_, i) => (i % 4 === 0 ? 1 : 0)), 4));
  const mesh = new THREE.SkinnedMesh(g, new THREE.MeshBasicMaterial({ color: 0x3366ff }));
  mesh.name = 'visor';
  mesh.castShadow = false;
  mesh.receiveShadow = true;
  const bones = [new THREE.Bone(), new THREE.Bone()];
  bones.forEach((b, i) => { b.name = `visor${i}`; });
  bones[0].position.y = 2;
  bones[1].position.y = 0.2;
  bones[0].add(bones[1]);
  return { mesh, bones };
}

/** The character: root (moved, turned, scaled) ⊃ holder (moved, turned) ⊃ body; root ⊃ visor; bones under root. */
function makeCharacter() {
  const root = new THREE.Group();
  root.name = 'character';
  root.position.set(3, -1, 2);
  root.rotation.set(0.3, 0.7, 0);
  root.scale.setScalar(1.5);
  const holder = new THREE.Group();
  holder.position.set(0.5, 0, 0.2);
  holder.rotation.z = 0.2;
  root.add(holder);
  const body = makeBody();
  const visor = makeVisor();
  body.mesh.position.set(0, 0.1, 0);
  holder.add(body.mesh);
  visor.mesh.position.set(-0.1, 0, 0);
  visor.mesh.rotation.y = 0.3;
  root.add(visor.mesh, body.bones[0], visor.bones[0]);
  root.updateMatrixWorld(true);
  body.mesh.bind(new THREE.Skeleton(body.bones));
  visor.mesh.bind(new THREE.Skeleton(visor.bones));
  return { root, holder, body, visor };
}

/** three.js's own result for vertex i, world space: morph (relative deltas), then skin. */
function threeVertex(mesh: THREE.SkinnedMesh, i: number, out: THREE.Vector3): THREE.Vector3 {
  out.fromBufferAttribute(mesh.geometry.getAttribute('position'), i);
  const targets = mesh.geometry.morphAttributes.position ?? [];
  targets.forEach((t, k) => {
    const w = mesh.morphTargetInfluences?.[k] ?? 0;
    out.x += w * t.getX(i);
    out.y += w * t.getY(i);
    out.z += w * t.getZ(i);
  });
  return mesh.applyBoneTransform(i, out).applyMatrix4(mesh.matrixWorld);
}

/** Largest distance (world space) between the deformed mesh and three's skinning over the vertices `keep` accepts. */
function worstError(skin: SkinDeformer, keep: (i: number) => boolean = () => true): { worst: number; checked: number } {
  const src = skin.deformer.sourceVertex!;
  const position = skin.mesh.geometry.getAttribute('position');
  const a = new THREE.Vector3(), b = new THREE.Vector3();
  let worst = 0, checked = 0;
  skin.mesh.updateWorldMatrix(true, false);
  for (let o = 0; o < src.length; o++) {
    if (!keep(src[o])) continue;
    threeVertex(skin.source, src[o], a);
    b.fromBufferAttribute(position, o).applyMatrix4(skin.mesh.matrixWorld);
    worst = Math.max(worst, a.distanceTo(b));
    checked++;
  }
  return { worst, checked };
}

/** True for a vertex bound 100 % to one joint. */
function rigid(mesh: THREE.SkinnedMesh): (i: number) => boolean {
  const w = mesh.geometry.getAttribute('skinWeight');
  return (i) => [0, 1, 2, 3].some((k) => w.getComponent(i, k) === 1);
}

function pose(c: ReturnType<typeof makeCharacter>, big = false): void {
  const [b0, b1] = c.body.bones;
  b0.rotation.set(0.2, 0.4, 0.1);
  b1.rotation.set(0.3, -0.5, big ? 2.4 : 1.1);
  c.visor.bones[1].rotation.set(0.4, 0.9, -0.2);
  c.visor.bones[1].position.set(0, 0.2, 0);
  if (big) {
    b0.position.set(0.5, 0.3, -0.4);
    c.visor.bones[0].rotation.x = -1.2;
    c.visor.bones[1].position.set(4, 0.5, -3);
  }
  c.body.mesh.morphTargetInfluences![0] = 0.6;
}

/** Every deformed vertex of `skin` inside its geometry's bounding box and sphere (local space). */
function outsideBounds(skin: SkinDeformer): number {
  const g = skin.mesh.geometry;
  const p = g.getAttribute('position');
  const v = new THREE.Vector3();
  let worst = 0;
  for (let i = 0; i < p.count; i++) {
    v.fromBufferAttribute(p, i);
    worst = Math.max(worst, v.distanceTo(g.boundingSphere!.center) - g.boundingSphere!.radius, g.boundingBox!.distanceToPoint(v));
  }
  return worst;
}

describe('GcsCharacter', () => {
  test('deformed meshes take the sources\' places: parent, transform, material, flags, attributes', () => {
    const c = makeCharacter();
    const bodyLayers = c.body.mesh.layers.mask;
    const character = new GcsCharacter(gcs, c.root);
    expect(character.skins.map((s) => s.source)).toEqual([c.body.mesh, c.visor.mesh]);
    expect(character.method).toBe('gcs');
    for (const skin of character.skins) {
      const { source, mesh } = skin;
      expect(mesh.parent).toBe(source.parent);
      const siblings = source.parent!.children;
      expect(siblings.indexOf(mesh)).toBe(siblings.indexOf(source) + 1); // animation tracks bind to the source first
      expect(mesh.position.toArray()).toEqual(source.position.toArray());
      expect(mesh.quaternion.toArray()).toEqual(source.quaternion.toArray());
      expect(mesh.scale.toArray()).toEqual(source.scale.toArray());
      mesh.updateWorldMatrix(true, false); // as the renderer does: no double transform
      expect(mesh.matrixWorld.elements).toEqual(source.matrixWorld.elements);
      expect(mesh.material).toBe(source.material); // shared, not cloned
      expect(mesh.castShadow).toBe(source.castShadow);
      expect(mesh.receiveShadow).toBe(source.receiveShadow);
      expect(mesh.name).toBe(source.name);
      expect(mesh.renderOrder).toBe(source.renderOrder);
      expect(mesh.visible).toBe(true);
      expect(mesh.frustumCulled).toBe(true);
      expect((mesh as THREE.SkinnedMesh).isSkinnedMesh).toBeFalsy();
      expect(source.layers.mask).toBe(0); // out of render, shadows and raycasts; still in the graph
      expect(mesh.geometry.getAttribute('skinIndex')).toBeUndefined();
      expect(Object.keys(mesh.geometry.morphAttributes)).toEqual([]); // morphs are in the deformer, not applied twice
    }
    expect(character.skins[0].mesh.layers.mask).toBe(bodyLayers);
    expect(character.meshes).toEqual(character.skins.map((s) => s.mesh));
    // Every non-skinning attribute carried, same type, reordered through sourceVertex.
    const body = character.skins[0];
    const src = body.deformer.sourceVertex!;
    const g = body.mesh.geometry, sg = c.body.mesh.geometry;
    for (const name of ['uv', 'color']) {
      const a = g.getAttribute(name) as THREE.BufferAttribute, s = sg.getAttribute(name) as THREE.BufferAttribute;
      expect(a.array.constructor).toBe(s.array.constructor);
      expect(a.itemSize).toBe(s.itemSize);
      expect(a.normalized).toBe(s.normalized);
      for (let o = 0; o < src.length; o++)
        for (let k = 0; k < a.itemSize; k++) expect(a.array[o * a.itemSize + k]).toBe(s.array[src[o] * s.itemSize + k]);
    }
    expect(g.getAttribute('tangent').itemSize).toBe(4);
    expect(body.deformsTangents).toBe(true);
    expect(character.skins[1].mesh.geometry.getAttribute('uv')).toBeDefined();
    character.dispose();
  });

  test('positions equal three.js skinning after the morph: LBS everywhere, GCS where bound to one joint', () => {
    const c = makeCharacter();
    pose(c);
    const lbs = new GcsCharacter(gcs, c.root, { method: 'lbs' });
    lbs.update();
    for (const skin of lbs.skins) {
      const { worst, checked } = worstError(skin);
      expect(checked).toBe(skin.source.geometry.getAttribute('position').count);
      expect(worst, skin.source.name).toBeLessThan(1e-5);
    }
    // The morph really is in there: with the influence at 0 the upper part is 0.5 × narrower.
    expect(lbs.skins[0].deformer.morphTargetCount).toBe(1);
    lbs.dispose();

    const character = new GcsCharacter(gcs, c.root); // GCS, the default
    character.update();
    const body = worstError(character.skins[0], rigid(c.body.mesh));
    expect(body.checked).toBeGreaterThan(300);
    expect(body.worst).toBeLessThan(1e-5);
    const visor = worstError(character.skins[1]); // all of it is bound to one joint
    expect(visor.checked).toBe(c.visor.mesh.geometry.getAttribute('position').count);
    expect(visor.worst).toBeLessThan(1e-5);
    // Tangents turn with the skin: for a vertex bound to one joint, three's skinning of the direction.
    const skin = character.skins[0];
    const t = skin.mesh.geometry.getAttribute('tangent');
    const st = c.body.mesh.geometry.getAttribute('tangent');
    const isRigid = rigid(c.body.mesh);
    const src = skin.deformer.sourceVertex!;
    const ref = new THREE.Vector4(), got = new THREE.Vector3();
    let worst = 0;
    for (let o = 0; o < src.length; o++) {
      if (!isRigid(src[o])) continue;
      ref.set(st.getX(src[o]), st.getY(src[o]), st.getZ(src[o]), 0);
      c.body.mesh.applyBoneTransform(src[o], ref);
      const r = new THREE.Vector3(ref.x, ref.y, ref.z).normalize();
      got.set(t.getX(o), t.getY(o), t.getZ(o));
      worst = Math.max(worst, got.distanceTo(r));
      expect(t.getW(o)).toBe(st.getW(src[o]));
    }
    expect(worst).toBeLessThan(1e-5);
    character.dispose();
  });

  test('an AnimationMixer drives bones and morph influences through the sources (same names)', () => {
    const c = makeCharacter();
    const character = new GcsCharacter(gcs, c.root, { method: 'lbs' });
    const q = new THREE.Quaternion().setFromEuler(new THREE.Euler(0, 0, 1.3));
    const clip = new THREE.AnimationClip('bend', 1, [
      new THREE.QuaternionKeyframeTrack('body1.quaternion', [0, 1], [0, 0, 0, 1, q.x, q.y, q.z, q.w]),
      new THREE.NumberKeyframeTrack('body.morphTargetInfluences[0]', [0, 1], [0, 1]),
      new THREE.VectorKeyframeTrack('visor1.position', [0, 1], [0, 0.2, 0, 0.4, 0.2, 0.3]),
    ]);
    const mixer = new THREE.AnimationMixer(c.root); // made after the character: binds by name
    mixer.clipAction(clip).play();
    mixer.setTime(0.75);
    character.update();
    expect(c.body.mesh.morphTargetInfluences![0]).toBeCloseTo(0.75, 6);
    expect(c.visor.bones[1].position.x).toBeCloseTo(0.3, 6);
    for (const skin of character.skins) expect(worstError(skin).worst, skin.source.name).toBeLessThan(1e-5);
    character.dispose();
  });

  test('bounds follow the animation: every vertex inside after a big pose change, every method; culling sees the moved part', () => {
    const c = makeCharacter();
    const bindCentre = new THREE.Vector3();
    for (const method of ['gcs', 'lbs', 'dqs', 'classic'] as DeformerKind[]) {
      pose(c, false);
      const character = new GcsCharacter(gcs, c.root, { method });
      const visor = character.skins[1];
      visor.mesh.geometry.boundingSphere!.getBoundingBox(new THREE.Box3()).getCenter(bindCentre);
      bindCentre.applyMatrix4(visor.mesh.matrixWorld);
      pose(c, true);
      character.update();
      for (const skin of character.skins) expect(outsideBounds(skin), `${method} ${skin.source.name}`).toBeLessThanOrEqual(0);
      // A narrow camera on the visor's new place sees it (bounds moved); on its old place, not.
      const now = new THREE.Vector3();
      visor.mesh.geometry.boundingBox!.getCenter(now).applyMatrix4(visor.mesh.matrixWorld);
      expect(now.distanceTo(bindCentre)).toBeGreaterThan(2);
      const frustum = new THREE.Frustum();
      const sees = (target: THREE.Vector3) => {
        const camera = new THREE.PerspectiveCamera(5, 1, 0.1, 100);
        camera.position.copy(target).add(new THREE.Vector3(0, 0, 10));
        camera.lookAt(target);
        camera.updateMatrixWorld(true);
        frustum.setFromProjectionMatrix(new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
        return frustum.intersectsObject(visor.mesh);
      };
      expect(sees(now), method).toBe(true);
      // Not just grown: they left the old place (the classic model's bounds are 5× generous: not there).
      if (method !== 'classic') expect(sees(bindCentre), method).toBe(false);
      character.dispose();
    }
  });

  test('a raycast hits the deformed skin where the bind pose misses, and never the hidden source', () => {
    const c = makeCharacter();
    c.body.bones[1].rotation.z = Math.PI / 2; // the upper half now points to −x (mesh space)
    const character = new GcsCharacter(gcs, c.root);
    character.update();
    const skin = character.skins[0], body = skin.mesh;
    body.updateWorldMatrix(true, false);
    // Mesh space: the bend turns about z (the bones' z is the mesh's), so the upper half's axis
    // stays in the xy plane. Aim along −z at the centre of a ring of the bent upper half.
    const src = skin.deformer.sourceVertex!, y = c.body.mesh.geometry.getAttribute('position');
    const centre = new THREE.Vector3(), p = new THREE.Vector3();
    let count = 0;
    for (let o = 0; o < src.length; o++) {
      if (Math.abs(y.getY(src[o]) - 1.7) > 1e-4) continue;
      centre.add(p.fromBufferAttribute(body.geometry.getAttribute('position'), o));
      count++;
    }
    centre.divideScalar(count);
    expect(Math.abs(centre.x)).toBeGreaterThan(0.5); // far from the bind pose's axis (x = 0)
    const origin = new THREE.Vector3(centre.x, centre.y, 3), dir = new THREE.Vector3(0, 0, -1);
    const toWorld = (o: THREE.Vector3, d: THREE.Vector3) => new THREE.Raycaster(
      o.clone().applyMatrix4(body.matrixWorld), d.clone().transformDirection(body.matrixWorld));
    const hits = toWorld(origin, dir).intersectObject(c.root, true);
    expect(hits.length).toBeGreaterThan(0);
    expect(hits[0].object).toBe(body);
    expect(hits.some((h) => h.object === c.body.mesh)).toBe(false);
    const local = body.worldToLocal(hits[0].point.clone());
    expect(local.x).toBeCloseTo(centre.x, 4);
    expect(local.z).toBeGreaterThan(0.9 * RADIUS);
    expect(local.z).toBeLessThan(RADIUS + 1e-4);
    // The same ray on the bind-pose geometry misses.
    const bind = new THREE.Mesh(c.body.mesh.geometry, new THREE.MeshBasicMaterial());
    bind.matrixAutoUpdate = false;
    bind.matrix.copy(body.matrixWorld);
    bind.matrixWorld.copy(body.matrixWorld);
    expect(toWorld(origin, dir).intersectObject(bind).length).toBe(0);
    // And a ray through the old place of the upper half misses the deformed body.
    expect(toWorld(new THREE.Vector3(0, 1.7, 3), dir).intersectObject(body).length).toBe(0);
    character.dispose();
  });

  test('rebuild switches every skin, all or nothing; morphs survive it', () => {
    const c = makeCharacter();
    pose(c);
    const character = new GcsCharacter(gcs, c.root, { gcs: { sections: 5 } });
    const meshes = [...character.meshes];
    const before = character.skins.map((s) => s.deformer);
    expect(() => character.rebuild('gcs', { gcs: { sections: 1 } })).toThrow(GcsError);
    expect(character.skins.map((s) => s.deformer)).toEqual(before);
    expect(before.every((d) => !d.disposed)).toBe(true);
    const geometry = meshes[0].geometry;
    character.rebuild('lbs');
    expect(character.method).toBe('lbs');
    expect(before.every((d) => d.disposed)).toBe(true);
    expect(character.meshes).toEqual(meshes); // the same objects, in the same place
    expect(meshes[0].geometry).not.toBe(geometry);
    character.update();
    for (const skin of character.skins) expect(worstError(skin).worst).toBeLessThan(1e-5);
    character.rebuild('classic');
    character.update();
    expect(character.skins[0].deformer.morphTargetCount).toBe(0); // the classic model skips morphs
    expect(character.skins[0].mesh.material).toBe(c.body.mesh.material);
    {
      // The source's maps on the classic output: a carried vertex copies its own source vertex's uv
      // and colour (this two-bone body is all carried; resampled vertices: the CesiumMan test).
      const skin = character.skins[0];
      const d = skin.deformer as ClassicDeformer;
      const geometry = skin.mesh.geometry;
      const uv = geometry.getAttribute('uv'), colour = geometry.getAttribute('color');
      const srcUv = c.body.mesh.geometry.getAttribute('uv'), srcColour = c.body.mesh.geometry.getAttribute('color');
      expect(uv.count).toBe(d.vertexCount);
      expect(colour.count).toBe(d.vertexCount);
      const sourceOf = d.sourceOfVertex;
      for (let o = 0; o < d.vertexCount; o++) {
        if (sourceOf[o] < 0) continue;
        expect(uv.getX(o)).toBe(srcUv.getX(sourceOf[o]));
        expect(uv.getY(o)).toBe(srcUv.getY(sourceOf[o]));
        expect(colour.getW(o)).toBeCloseTo(srcColour.getW(sourceOf[o]), 6);
      }
    }
    character.rebuild('gcs');
    character.update();
    expect(worstError(character.skins[1]).worst).toBeLessThan(1e-5);
    character.dispose();
  });

  test.skipIf(!sharedModels().files.some((f) => f.endsWith('CesiumMan.glb')))('classic on a textured character: every resampled vertex takes the uv of the closest source point (brute force)', async () => {
    const model = await loadGlb(sharedModels().files.find((f) => f.endsWith('CesiumMan.glb'))!);
    const character = new GcsCharacter(gcs, model.scene, { method: 'classic' });
    const skin = character.skins[0];
    const d = skin.deformer as ClassicDeformer;
    const src = skin.source.geometry;
    const uv = skin.mesh.geometry.getAttribute('uv'), srcUv = src.getAttribute('uv');
    expect(uv.count).toBe(d.vertexCount);
    expect(skin.mesh.material).toBe(skin.source.material);
    d.deform(new Float32Array(16 * d.jointCount).map((_, i) => ((i % 16) % 5 === 0 ? 1 : 0)));
    const sourceOf = d.sourceOfVertex, P = src.getAttribute('position'), index = src.index!;
    const tri = new THREE.Triangle(), p = new THREE.Vector3(), q = new THREE.Vector3(), bary = new THREE.Vector3();
    const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
    const resampled = [...sourceOf.keys()].filter((o) => sourceOf[o] < 0);
    expect(resampled.length).toBeGreaterThan(1000);
    let worst = 0;
    for (const o of resampled.filter((_, i) => i % 97 === 0)) {
      p.fromArray(d.positions, 3 * o);
      let best = Infinity, bu = 0, bv = 0;
      for (let t = 0; t < index.count; t += 3) {
        const [ia, ib, ic] = [index.getX(t), index.getX(t + 1), index.getX(t + 2)];
        tri.set(a.fromBufferAttribute(P, ia), b.fromBufferAttribute(P, ib), c.fromBufferAttribute(P, ic));
        tri.closestPointToPoint(p, q);
        const dist = q.distanceTo(p);
        if (dist < best - 1e-9) {
          best = dist;
          tri.getBarycoord(q, bary);
          bu = bary.x * srcUv.getX(ia) + bary.y * srcUv.getX(ib) + bary.z * srcUv.getX(ic);
          bv = bary.x * srcUv.getY(ia) + bary.y * srcUv.getY(ib) + bary.z * srcUv.getY(ic);
        }
      }
      worst = Math.max(worst, Math.hypot(uv.getX(o) - bu, uv.getY(o) - bv));
    }
    expect(worst).toBeLessThan(1e-4);
    character.dispose();
  });

  test('an invisible source hides its deformed mesh (and skips its deform); dispose restores the originals and frees', () => {
    const c = makeCharacter();
    const layers = [c.body.mesh.layers.mask, c.visor.mesh.layers.mask];
    const parents = [c.body.mesh.parent, c.visor.mesh.parent];
    const children = parents.map((p) => p!.children.length);
    const character = new GcsCharacter(gcs, c.root);
    c.visor.mesh.visible = false;
    character.update();
    expect(character.skins[1].mesh.visible).toBe(false);
    expect(new THREE.Raycaster(new THREE.Vector3(0, 0, 10), new THREE.Vector3(0, 0, -1)).intersectObject(character.skins[1].mesh)).toEqual([]);
    c.visor.mesh.visible = true;
    character.update();
    expect(character.skins[1].mesh.visible).toBe(true);
    const deformers = character.skins.map((s) => s.deformer);
    const meshes = [...character.meshes];
    character.dispose();
    expect(character.disposed).toBe(true);
    expect(deformers.every((d) => d.disposed)).toBe(true);
    expect(character.skins.every((s) => s.disposed)).toBe(true);
    expect(meshes.every((m) => m.parent === null)).toBe(true);
    expect([c.body.mesh.layers.mask, c.visor.mesh.layers.mask]).toEqual(layers);
    expect([c.body.mesh.parent, c.visor.mesh.parent]).toEqual(parents);
    expect(parents.map((p) => p!.children.length)).toEqual(children);
    expect(c.body.mesh.material).toBeInstanceOf(THREE.MeshStandardMaterial); // not disposed or replaced
    expect(() => character.update()).toThrow(/disposed/);
    character.dispose(); // twice is fine
    // The same root can be driven again.
    const again = new GcsCharacter(gcs, c.root, { method: 'dqs' });
    again.update();
    again.dispose();
  });

  test('filter, errors: no skinned mesh; a parentless SkinnedMesh as the root gets its deformed mesh as a child', () => {
    expect(() => new GcsCharacter(gcs, new THREE.Group())).toThrow(GcsError);
    const c = makeCharacter();
    const only = new GcsCharacter(gcs, c.root, { filter: (m) => m.name === 'body' });
    expect(only.skins.map((s) => s.source)).toEqual([c.body.mesh]);
    expect(c.visor.mesh.layers.mask).toBe(1);
    only.dispose();
    const lone = c.visor.mesh;
    c.root.remove(lone);
    c.root.updateMatrixWorld(true);
    const character = new GcsCharacter(gcs, lone, { method: 'lbs' });
    expect(character.skins[0].mesh.parent).toBe(lone);
    character.update();
    expect(worstError(character.skins[0]).worst).toBeLessThan(1e-5);
    character.dispose();
    expect(lone.children).toEqual([]);
    expect(lone.layers.mask).toBe(1);
  });
});

const shared = sharedModels();
describe('real characters (../shared/models)', () => {
  test.skipIf(!shared.files.length)(`every skin of every model in place, bounds hold over the clips; LBS equals three.js ${shared.reason ?? ''}`, async () => {
    for (const file of shared.files) {
      const model = await loadGlb(file);
      const character = new GcsCharacter(gcs, model.scene, { method: 'lbs' });
      expect(character.skins.length).toBe(model.skinnedMeshes.length);
      const mixer = new THREE.AnimationMixer(model.scene);
      for (const clip of model.clips.slice(0, 3)) {
        mixer.stopAllAction();
        mixer.clipAction(clip).play();
        for (let f = 0; f < 8; f++) {
          mixer.setTime((clip.duration * f) / 8);
          // Skinned morph targets, if any, at non-zero weights (none of the four shared models has
          // one: RobotExpressive's face morphs are on unskinned meshes; the programmatic body has).
          for (const m of model.skinnedMeshes)
            m.morphTargetInfluences?.forEach((_, k, a) => { a[k] = 0.3 + 0.1 * ((k + f) % 5); });
          character.update();
          for (const skin of character.skins) {
            expect(outsideBounds(skin), file).toBeLessThanOrEqual(0);
            // Relative to the model's size (some are in centimetres).
            const size = skin.rig.height * skin.source.matrixWorld.getMaxScaleOnAxis();
            expect(worstError(skin).worst / size, `${file} ${skin.source.name}`).toBeLessThan(1e-5);
          }
        }
      }
      character.rebuild('gcs');
      character.update();
      for (const skin of character.skins) expect(outsideBounds(skin), file).toBeLessThanOrEqual(0);
      character.dispose();
      model.skinnedMeshes.forEach((m) => expect(m.layers.mask).not.toBe(0));
    }
  });
});
