/**
 * three.js adapter: a THREE.Mesh whose position and normal attributes ARE the deformer's
 * wasm-memory views, driven by a SkinnedMesh's skeleton (and so by its AnimationMixer).
 *
 *   const skin = new SkinDeformer(gcs, skinnedMesh, { method: 'gcs', gcs: { sections: 8 } });
 *   scene.add(skin.mesh);
 *   // each frame: mixer.update(dt); skin.update(); renderer.render(scene, camera);
 */
import * as THREE from 'three';
import { GcsError } from './errors.js';
import type { ClassicOptions, Deformer, DeformerKind, GcsOptions, GcsSkin, Rig, RigInput } from './index.js';

export interface SkinDeformerOptions {
  /** Which deformer drives the mesh. Default 'gcs'. */
  method?: DeformerKind;
  gcs?: GcsOptions;
  classic?: ClassicOptions;
  /** Material of the output mesh (default: a MeshStandardMaterial like the source's colour). */
  material?: THREE.Material | THREE.Material[];
}

/** Reads the rig (bind-pose mesh, skin, skeleton) out of a SkinnedMesh as GLTFLoader gives it. */
export function rigInputFromSkinnedMesh(source: THREE.SkinnedMesh): RigInput {
  if (!source || !(source as THREE.SkinnedMesh).isSkinnedMesh || !source.skeleton)
    throw new GcsError('NO_SKIN', 'the object is not a skinned mesh (no skeleton): gcs-skin needs a THREE.SkinnedMesh');
  const geometry = source.geometry;
  const position = geometry.getAttribute('position');
  const skinIndex = geometry.getAttribute('skinIndex');
  const skinWeight = geometry.getAttribute('skinWeight');
  if (!position) throw new GcsError('NO_SKIN', 'the skinned mesh has no position attribute');
  if (!skinIndex || !skinWeight)
    throw new GcsError('NO_SKIN', 'the mesh has no skin weights (skinIndex/skinWeight attributes): it cannot be deformed by bones');
  const n = position.count;
  const positions = new Float32Array(n * 3);
  const joints = new Uint32Array(n * 4);
  const weights = new Float32Array(n * 4);
  // Build-time only: getX/getY… handle interleaved and normalised attributes uniformly.
  for (let i = 0; i < n; i++) {
    positions[3 * i] = position.getX(i);
    positions[3 * i + 1] = position.getY(i);
    positions[3 * i + 2] = position.getZ(i);
    for (let k = 0; k < 4; k++) {
      joints[4 * i + k] = skinIndex.getComponent(i, k);
      weights[4 * i + k] = skinWeight.getComponent(i, k);
    }
  }
  const normalAttr = geometry.getAttribute('normal');
  let normals: Float32Array | null = null;
  if (normalAttr) {
    normals = new Float32Array(n * 3);
    for (let i = 0; i < n; i++) {
      normals[3 * i] = normalAttr.getX(i);
      normals[3 * i + 1] = normalAttr.getY(i);
      normals[3 * i + 2] = normalAttr.getZ(i);
    }
  }
  let indices: Uint32Array;
  if (geometry.index) {
    indices = Uint32Array.from(geometry.index.array as ArrayLike<number>);
  } else {
    indices = new Uint32Array(n - (n % 3));
    for (let i = 0; i < indices.length; i++) indices[i] = i;
  }
  const bones = source.skeleton.bones;
  const boneIndex = new Map<THREE.Object3D, number>();
  bones.forEach((b, i) => boneIndex.set(b, i));
  const parents = new Int32Array(bones.length);
  bones.forEach((bone, i) => {
    let p: THREE.Object3D | null = bone.parent;
    while (p && !boneIndex.has(p)) p = p.parent;
    parents[i] = p ? boneIndex.get(p)! : -1;
  });
  // Mesh-space inverse binds: three skins bindMatrixInverse · bone · boneInverse · bindMatrix.
  const inverseBindMatrices = new Float32Array(bones.length * 16);
  const m = new THREE.Matrix4();
  source.skeleton.boneInverses.forEach((inv, i) => {
    m.multiplyMatrices(inv, source.bindMatrix);
    inverseBindMatrices.set(m.elements, 16 * i);
  });
  return { positions, normals, indices, joints, weights, parents, inverseBindMatrices };
}

/**
 * A mesh deformed in wasm, driven by `source`'s skeleton. `mesh` carries the source's world
 * transform: add it to the scene at the top level (or under an untransformed group).
 */
export class SkinDeformer {
  readonly source: THREE.SkinnedMesh;
  readonly rig: Rig;
  readonly mesh: THREE.Mesh;
  deformer!: Deformer;
  private method: DeformerKind;
  private options: SkinDeformerOptions;
  private readonly skin: Float32Array;
  private readonly tmp = new THREE.Matrix4();
  private readonly root: THREE.Object3D;
  private readonly sourceUv: THREE.BufferAttribute | THREE.InterleavedBufferAttribute | undefined;

  constructor(readonly gcs: GcsSkin, source: THREE.SkinnedMesh, options: SkinDeformerOptions = {}) {
    this.rig = gcs.createRig(rigInputFromSkinnedMesh(source));
    this.source = source;
    this.options = { ...options };
    this.method = options.method ?? 'gcs';
    this.skin = new Float32Array(this.rig.jointCount * 16);
    this.sourceUv = source.geometry.getAttribute('uv');
    let root: THREE.Object3D = source;
    while (root.parent) root = root.parent;
    this.root = root;
    const material = options.material ?? new THREE.MeshStandardMaterial({ color: 0xc8a07d, roughness: 0.7 });
    this.mesh = new THREE.Mesh(new THREE.BufferGeometry(), material);
    this.mesh.matrixAutoUpdate = false;
    this.mesh.frustumCulled = false; // the bind-pose bounds do not follow the animation
    try {
      this.rebuild(this.method, options);
    } catch (e) {
      this.rig.dispose();
      throw e;
    }
  }

  /** Rebuilds the deformer (e.g. a new section count); the geometry is replaced. */
  rebuild(method: DeformerKind = this.method, options: { gcs?: GcsOptions; classic?: ClassicOptions } = {}): void {
    const gcsOptions = { ...this.options.gcs, ...options.gcs };
    const classicOptions = { ...this.options.classic, ...options.classic };
    // Build first: if it throws, the current deformer and geometry stay as they were.
    const next = method === 'gcs' ? this.rig.buildGcs(gcsOptions)
      : method === 'classic' ? this.rig.buildClassic(classicOptions) : this.rig.build(method);
    this.deformer?.dispose();
    this.deformer = next;
    this.method = method;
    this.options = { ...this.options, gcs: gcsOptions, classic: classicOptions, method };
    const geometry = new THREE.BufferGeometry();
    geometry.setIndex(new THREE.BufferAttribute(next.indices, 1));
    geometry.setAttribute('position', new THREE.BufferAttribute(next.positions, 3).setUsage(THREE.DynamicDrawUsage));
    geometry.setAttribute('normal', new THREE.BufferAttribute(next.normals, 3).setUsage(THREE.DynamicDrawUsage));
    const source = next.sourceVertex;
    if (source && this.sourceUv) {
      const uv = new Float32Array(source.length * 2);
      for (let i = 0; i < source.length; i++) {
        uv[2 * i] = this.sourceUv.getX(source[i]);
        uv[2 * i + 1] = this.sourceUv.getY(source[i]);
      }
      geometry.setAttribute('uv', new THREE.BufferAttribute(uv, 2));
    }
    const old = this.mesh.geometry;
    this.mesh.geometry = geometry;
    old.dispose();
    this.update();
  }

  /**
   * Poses from the skeleton and deforms. Call once per frame, after the mixer. By default it
   * first updates the world matrices of the source's scene graph (the bones as the mixer left
   * them); pass `{ updateMatrixWorld: false }` when several deformers share a scene and the
   * caller has already done that once this frame.
   */
  update(options: { updateMatrixWorld?: boolean } = {}): void {
    const source = this.source;
    if (options.updateMatrixWorld !== false) this.root.updateMatrixWorld();
    const bones = source.skeleton.bones;
    const inverses = source.skeleton.boneInverses;
    const skin = this.skin;
    const tmp = this.tmp;
    for (let j = 0; j < bones.length; j++) {
      // S_j in mesh space: bindMatrixInverse · boneWorld · boneInverse · bindMatrix.
      tmp.multiplyMatrices(bones[j].matrixWorld, inverses[j]);
      tmp.premultiply(source.bindMatrixInverse);
      tmp.multiply(source.bindMatrix);
      const e = tmp.elements;
      for (let k = 0; k < 16; k++) skin[16 * j + k] = e[k];
    }
    this.deformer.deform(skin);
    this.mesh.matrix.copy(source.matrixWorld);
    this.mesh.matrixWorld.copy(source.matrixWorld);
    this.syncAttributes();
  }

  /** Points the attributes at live views (memory growth detaches old ones) and flags the upload. */
  private syncAttributes(): void {
    const geometry = this.mesh.geometry;
    const position = geometry.getAttribute('position') as THREE.BufferAttribute;
    const normal = geometry.getAttribute('normal') as THREE.BufferAttribute;
    const positions = this.deformer.positions;
    if (position.array !== positions) position.array = positions;
    const normals = this.deformer.normals;
    if (normal.array !== normals) normal.array = normals;
    position.needsUpdate = true;
    normal.needsUpdate = true;
  }

  get currentMethod(): DeformerKind {
    return this.method;
  }

  /** Frees the wasm memory and the geometry (not the material, which the caller may share). */
  dispose(): void {
    this.deformer?.dispose();
    this.rig.dispose();
    this.mesh.geometry.dispose();
  }
}
