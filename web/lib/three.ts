/**
 * three.js adapter: THREE.Meshes whose position and normal attributes ARE the deformers'
 * wasm-memory views, driven by SkinnedMeshes' skeletons (and so by an AnimationMixer).
 *
 * A whole character (a glTF scene or any Object3D), in place:
 *
 *   const character = new GcsCharacter(gcs, gltf.scene);      // every SkinnedMesh under it
 *   scene.add(gltf.scene);
 *   const mixer = new THREE.AnimationMixer(gltf.scene);
 *   // each frame: mixer.update(dt); character.update(); renderer.render(scene, camera);
 *   // at the end: character.dispose();                        // the SkinnedMeshes come back
 *
 * One SkinnedMesh, its deformed mesh placed by hand (carries the source's world transform):
 *
 *   const skin = new SkinDeformer(gcs, skinnedMesh, { method: 'gcs', gcs: { sections: 8 } });
 *   scene.add(skin.mesh);
 *   // each frame: mixer.update(dt); skin.update(); renderer.render(scene, camera);
 */
import * as THREE from 'three';
import { GcsError } from './errors.js';
import { CLASSIC_LIMITS, ClassicDeformer, type ClassicOptions, type Deformer, type DeformerKind, type GcsDeformer, type GcsOptions, type GcsSkin, type Rig, type RigInput } from './index.js';
import { transferSurfaceAttributes } from './surface-attributes.js';
import { bindGeometry, identitySkin, remapAttribute, SKINNING_ATTRIBUTES } from './gpu/bind.js';
import { disposeGpuMaterials, type GpuMaterialKit, type GpuMaterials } from './gpu/kit.js';
import type { GpuPath } from './gpu/layout.js';
import { GpuSections } from './gpu/sections.js';
import { glslKit } from './gpu/webgl-materials.js';

/** Where the per-vertex work runs: 'cpu' (wasm fills the vertex buffers) or 'gpu' (the vertex shader applies GCS section transforms). */
export type Backend = 'cpu' | 'gpu';

export interface SkinDeformerOptions {
  /** Which deformer drives the mesh. Default 'gcs'. */
  method?: DeformerKind;
  gcs?: GcsOptions;
  classic?: ClassicOptions;
  /** Material of the output mesh. Default: the source's own material (the same object, shared, not cloned). */
  material?: THREE.Material | THREE.Material[];
  /**
   * Put the deformed mesh in the source's place: it is inserted under the source's parent, right
   * after it, with the source's local transform (kept in step by update()), and it mirrors
   * `source.visible`; the source leaves the render, the shadow passes and raycasts (its `layers`
   * are cleared, so its children still render and its bones still move). `dispose()` undoes it.
   * A source without a parent gets the deformed mesh as its child, at identity. Default false:
   * `mesh` is free and carries the source's world transform (add it at the top level).
   */
  inPlace?: boolean;
  /**
   * When the source geometry has a `tangent` attribute: 'deform' (default) turns the tangents
   * with the skin (a second deformer of the same kind, fed the tangents as its normals: one more
   * deform and a copy per frame); 'drop' leaves them out, and three.js derives the tangent frame
   * of normal maps from the deformed positions and uvs (screen-space derivatives). Carrying the
   * bind-pose tangents unchanged would tilt normal maps wherever the skin bends, so that is not
   * offered. Ignored by the classic model.
   */
  tangents?: 'deform' | 'drop';
  /**
   * 'cpu' (default): wasm deforms every vertex and three.js uploads the vertex buffers each frame.
   * 'gpu': the mesh stays on the GPU in the bind pose; per frame wasm computes only the joint
   * poses (weights criterion; about 1 KB) or the section transforms (a few KB), into a float
   * texture, and the vertex shader of a patched clone of the material applies them (docs/gpu.md;
   * see gpuPath). GCS only: other methods, and materials that cannot be
   * patched (ShaderMaterial, node materials), fall back to 'cpu' — `backend` tells which runs,
   * `backendNote` why, and one console warning says so. The same happens at the first draw by a
   * WebGPURenderer, which never runs the patch: gcs-skin/webgpu is the GPU backend for it (TSL).
   */
  backend?: Backend;
  /**
   * GPU backend: what wasm hands the GPU per frame. 'auto' (default): 'joints' for the weights
   * criterion (the joint poses, 64 bytes per joint; the shader blends each section from them and a
   * static table), 'sections' for 'y' and 'axial' (the section transforms, 48 bytes per section).
   * 'sections' forces the section-level path; 'joints' with 'y' or 'axial' is GcsError
   * 'INVALID_ARGUMENT'.
   */
  gpuPath?: GpuPath | 'auto';
  /** @internal How materials run GCS on the GPU (gcs-skin/webgpu passes its TSL kit). Default: the GLSL kit (WebGLRenderer). */
  gpuKit?: GpuMaterialKit;
  /** @internal The backend notes already warned about (a GcsCharacter shares one set: one warning per cause). */
  warned?: Set<string>;
}

/**
 * Writes the skin matrices S_j = bindMatrixInverse · boneWorld · boneInverse · bindMatrix (mesh
 * space, J × 16 floats, what deformers take) of `source`'s skeleton as it is posed now (world
 * matrices up to date) into `out` at `offset`. No allocation when `tmp` is given.
 */
export function writeSkinMatrices(source: THREE.SkinnedMesh, out: Float32Array, offset = 0, tmp = new THREE.Matrix4()): void {
  const bones = source.skeleton.bones;
  const inverses = source.skeleton.boneInverses;
  for (let j = 0; j < bones.length; j++) {
    tmp.multiplyMatrices(bones[j].matrixWorld, inverses[j]);
    tmp.premultiply(source.bindMatrixInverse);
    tmp.multiply(source.bindMatrix);
    const e = tmp.elements;
    const o = offset + 16 * j;
    for (let k = 0; k < 16; k++) out[o + k] = e[k];
  }
}

type AnyAttribute = THREE.BufferAttribute | THREE.InterleavedBufferAttribute;

/** Geometries already warned about (a rebuild with other options reads the same geometry again). */
const warnedInfluences = new WeakSet<THREE.BufferGeometry>();

/** Whether any vertex of a skin weight attribute has a weight above 0. */
function anyWeight(weights: AnyAttribute): boolean {
  for (let i = 0; i < weights.count; i++)
    for (let k = 0; k < weights.itemSize; k++) if (weights.getComponent(i, k) > 0) return true;
  return false;
}

/**
 * The second set of influences, as GLTFLoader keeps JOINTS_1/WEIGHTS_1 (`joints_1`/`weights_1`;
 * three's own skinning ignores them), or null when absent or all zero (the rig then costs what a
 * 4-influence one does). Where the first four sum to 1 (as GLTFLoader leaves them) and the second
 * set holds weight, the first four are scaled by 1 − Σ(second): a glTF's eight sum to 1. A third set (more than 8 influences) is beyond the core: said once per geometry.
 */
function secondInfluences(geometry: THREE.BufferGeometry): { joints: AnyAttribute; weights: AnyAttribute } | null {
  const extra = geometry.getAttribute('weights_2');
  if (extra && !warnedInfluences.has(geometry) && anyWeight(extra)) {
    warnedInfluences.add(geometry);
    console.warn('gcs-skin: the skinned mesh has more than 8 joint influences per vertex (joints_2/weights_2); only the first 8 are used ' +
      '(gcs-skin/gltf keeps the 8 largest and renormalises)');
  }
  const joints = geometry.getAttribute('joints_1'), weights = geometry.getAttribute('weights_1');
  if (!joints || !weights || joints.itemSize !== 4 || weights.itemSize !== 4 || !anyWeight(weights)) return null;
  return { joints, weights };
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
  const second = secondInfluences(geometry);
  const influences = second ? 8 : 4;
  const n = position.count;
  const positions = new Float32Array(n * 3);
  const joints = new Uint32Array(n * influences);
  const weights = new Float32Array(n * influences);
  // Build-time only: getX/getY… handle interleaved and normalised attributes uniformly.
  for (let i = 0; i < n; i++) {
    positions[3 * i] = position.getX(i);
    positions[3 * i + 1] = position.getY(i);
    positions[3 * i + 2] = position.getZ(i);
    for (let k = 0; k < 4; k++) {
      joints[influences * i + k] = skinIndex.getComponent(i, k);
      weights[influences * i + k] = skinWeight.getComponent(i, k);
    }
    if (second) {
      let first = 0, rest = 0;
      for (let k = 0; k < 4; k++) {
        joints[influences * i + 4 + k] = second.joints.getComponent(i, k);
        weights[influences * i + 4 + k] = second.weights.getComponent(i, k);
        first += weights[influences * i + k];
        rest += Math.max(0, weights[influences * i + 4 + k]);
      }
      // GLTFLoader scales the first four to sum 1 (SkinnedMesh.normalizeSkinWeights) and leaves the
      // second set alone; a glTF's eight sum to 1, so the first four had 1 − Σ(second) between them.
      if (Math.abs(first - 1) < 1e-3) for (let k = 0; k < 4; k++) weights[influences * i + k] *= Math.max(0, 1 - rest);
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
  return { positions, normals, indices, joints, weights, influences, parents, inverseBindMatrices };
}

/** Morph targets as relative deltas in the source's vertex order (glTF / three: morphTargetsRelative). */
interface MorphData {
  positions: ArrayLike<number>[];
  normals: ArrayLike<number>[] | null;
  /** Per target, the largest delta length: bounds grow by Σ |influence| · maxDelta. */
  maxDelta: Float32Array;
}

function morphData(geometry: THREE.BufferGeometry): MorphData | null {
  const targets = geometry.morphAttributes.position;
  if (!targets || targets.length === 0) return null;
  const base = geometry.getAttribute('position');
  const n = base.count;
  const relative = geometry.morphTargetsRelative;
  const deltas = (list: AnyAttribute[], baseAttr: AnyAttribute | undefined): ArrayLike<number>[] =>
    list.map((attr) => {
      const plain = attr as THREE.BufferAttribute;
      // The common glTF case, zero copy: setMorphTargets copies into wasm anyway.
      if (relative && !(attr as THREE.InterleavedBufferAttribute).isInterleavedBufferAttribute && !attr.normalized
        && attr.itemSize === 3 && plain.array instanceof Float32Array && plain.array.length === n * 3) return plain.array;
      const out = new Float32Array(n * 3);
      for (let i = 0; i < Math.min(n, attr.count); i++) {
        out[3 * i] = attr.getX(i) - (relative || !baseAttr ? 0 : baseAttr.getX(i));
        out[3 * i + 1] = attr.getY(i) - (relative || !baseAttr ? 0 : baseAttr.getY(i));
        out[3 * i + 2] = attr.getZ(i) - (relative || !baseAttr ? 0 : baseAttr.getZ(i));
      }
      return out;
    });
  const positions = deltas(targets, base);
  const normalTargets = geometry.morphAttributes.normal;
  const normalBase = geometry.getAttribute('normal');
  const normals = normalTargets && normalTargets.length === targets.length && normalBase ? deltas(normalTargets, normalBase) : null;
  const maxDelta = new Float32Array(positions.length);
  positions.forEach((d, t) => {
    let m = 0;
    for (let i = 0; i < d.length; i += 3) m = Math.max(m, d[i] * d[i] + d[i + 1] * d[i + 1] + d[i + 2] * d[i + 2]);
    maxDelta[t] = Math.sqrt(m);
  });
  return { positions, normals, maxDelta };
}

/** The lowest object that holds the source and all its bones: what update() refreshes. */
function commonAncestor(objects: THREE.Object3D[]): THREE.Object3D {
  const chain = (o: THREE.Object3D) => {
    const c: THREE.Object3D[] = [];
    for (let p: THREE.Object3D | null = o; p; p = p.parent) c.push(p);
    return c.reverse();
  };
  let common = chain(objects[0]);
  for (const o of objects.slice(1)) {
    const c = chain(o);
    let k = 0;
    while (k < common.length && k < c.length && common[k] === c[k]) k++;
    common = common.slice(0, k);
  }
  if (common.length) return common[common.length - 1];
  // Disjoint graphs: fall back to the source's topmost ancestor (the old behaviour).
  let root = objects[0];
  while (root.parent) root = root.parent;
  return root;
}

/** Brings `object`'s world matrix and its subtree's up to date, its ancestors first. */
function updateWorld(object: THREE.Object3D): void {
  // updateMatrixWorld, not updateWorldMatrix: SkinnedMesh overrides only the former (attached
  // bind mode refreshes bindMatrixInverse there).
  object.parent?.updateWorldMatrix(true, false);
  object.updateMatrixWorld(true);
}

/**
 * The output mesh: its geometry is the deformer's output, so raycasts hit the deformed skin.
 * Before a raycast its bounds are made exact (one pass over the positions; the raycast itself
 * walks every triangle), whereas frustum culling uses the per-frame bounds from the bones. An
 * in-place mesh hidden with its source is not deformed, so it is not raycast either.
 */
class DeformedMesh extends THREE.Mesh<THREE.BufferGeometry, THREE.Material | THREE.Material[]> {
  /** @internal Set by the SkinDeformer that owns the mesh. */
  exactBounds: (() => boolean) | null = null;
  /** @internal GPU backend: the CPU-deformed geometry that raycasts test (the drawn one stays in the bind pose). */
  raycastGeometry: THREE.BufferGeometry | null = null;
  override raycast(raycaster: THREE.Raycaster, intersects: THREE.Intersection[]): void {
    // false: an in-place mesh hidden with its source, not deformed since (stale): no hits.
    if (this.exactBounds && !this.exactBounds()) return;
    const drawn = this.geometry;
    if (this.raycastGeometry) this.geometry = this.raycastGeometry;
    try {
      super.raycast(raycaster, intersects);
    } finally {
      this.geometry = drawn;
    }
  }
}

/** Joints carrying skin and, per joint, the radius of its ball (see SkinDeformer.update()). */
interface BoneBalls {
  joints: Uint32Array;
  radii: Float32Array;
}

/** A deformer and the geometry around it, built but not yet shown (rebuilds are all-or-nothing). */
interface PendingBuild {
  method: DeformerKind;
  gcs: GcsOptions;
  classic: ClassicOptions;
  deformer: Deformer;
  /** Deforms the tangents (as its normals), or null. */
  tangentDeformer: Deformer | null;
  geometry: THREE.BufferGeometry;
  /** Per morph target, the largest delta length; null without morphs. */
  maxDelta: Float32Array | null;
  /** The GPU backend's state, or null (CPU). */
  gpu: GpuBuild | null;
  /** Why 'gpu' was asked for and 'cpu' runs, or ''. */
  note: string;
  /** The backend asked for. */
  backend: Backend;
  /** The GPU path asked for. */
  gpuPath: GpuPath | 'auto';
}

/** What rebuild() may change. */
export interface RebuildOptions {
  gcs?: GcsOptions;
  classic?: ClassicOptions;
  backend?: Backend;
  gpuPath?: GpuPath | 'auto';
}

/** The GPU backend of one build: section texture, patched materials, the geometry raycasts test. */
interface GpuBuild {
  sections: GpuSections;
  materials: GpuMaterials;
  raycast: THREE.BufferGeometry;
}

/**
 * A mesh deformed in wasm, driven by `source`'s skeleton.
 *
 * - Material: the source's own (the same object) unless `options.material`; castShadow,
 *   receiveShadow, name, layers, renderOrder, customDepthMaterial/customDistanceMaterial are
 *   copied at build. Every non-skinning attribute of the source (uv, uv1…, color, custom ones) is
 *   carried, reordered through `deformer.sourceVertex`; tangents per `options.tangents`.
 * - Placement: by default `mesh` carries the source's world transform (add it at the top level or
 *   under an untransformed group); with `inPlace: true` it replaces the source in its own graph.
 * - Frustum culling stays on: the bounds follow the animation (see update()).
 * - Morph targets (`geometry.morphAttributes.position`) are applied before skinning, as three.js
 *   does, with the source's `morphTargetInfluences` each frame. The classic model resamples the
 *   mesh, so it has no morphs and no tangents; its resampled vertices take the source's attributes
 *   (uv, colours…) at the closest point of the source surface in the bind pose, its carried ones
 *   their own source vertex's, so it wears the source's material (textures smear across UV seams).
 *
 * `dispose()` frees the wasm memory and the output geometry, removes `mesh` from its parent and,
 * in place, gives the source back its layers. Materials are never disposed (they are shared).
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
  private readonly point = new THREE.Vector3();
  /** What update() refreshes: the lowest common ancestor of the source and its bones. */
  private readonly scope: THREE.Object3D;
  private readonly inPlace: boolean;
  /** In place: the source's layers mask, given back by dispose(). */
  private readonly sourceLayers: number;
  /** In place, parentless source: the mesh is its child at identity. */
  private readonly childOfSource: boolean;
  private tangentRig: Rig | null = null;
  private tangentDeformer: Deformer | null = null;
  /** tangent w per source vertex (handedness), copied beside the deformed xyz. */
  private tangentW: Float32Array | null = null;
  private tangentOut: Float32Array | null = null;
  /** Per morph target, the largest delta length (null: no morphs this build). */
  private maxDelta: Float32Array | null = null;
  // Bounds from the bones: per joint j that carries skin, its bind position b_j (mesh space) and
  // the largest distance r_j from b_j to a vertex weighted to it.
  private readonly pivots: Float32Array;
  private readonly ownBalls: BoneBalls;
  private readonly nearBalls: BoneBalls;
  /** The balls and radius factor of the current build. */
  private balls: BoneBalls;
  private ballFactor = 1;
  private readonly box = new THREE.Box3();
  private readonly sphere = new THREE.Sphere();
  private exactFresh = false;
  private isDisposed = false;
  /** GPU backend of the current build, or null. */
  private gpu: GpuBuild | null = null;
  /** GPU backend: the deformer's CPU output matches the last update() (for raycasts). */
  private cpuFresh = false;
  private note = '';
  /** The material drawn by the CPU backend (the source's or options.material). */
  private readonly baseMaterial: THREE.Material | THREE.Material[];
  /** How the GPU backend's materials run GCS (GLSL for WebGLRenderer, TSL for WebGPURenderer). */
  private readonly kit: GpuMaterialKit;
  /** A geometry replaced during a draw (renderer fallback), freed at the next update(). */
  private retired: THREE.BufferGeometry | null = null;
  /** The backend notes already printed as console warnings. */
  private readonly warned: Set<string>;

  constructor(readonly gcs: GcsSkin, source: THREE.SkinnedMesh, options: SkinDeformerOptions = {}) {
    const input = rigInputFromSkinnedMesh(source);
    this.source = source;
    this.options = { ...options };
    this.method = options.method ?? 'gcs';
    this.inPlace = options.inPlace === true;
    this.rig = gcs.createRig(input);
    try {
      const tangent = source.geometry.getAttribute('tangent');
      if (tangent && tangent.itemSize >= 3 && options.tangents !== 'drop') {
        const n = tangent.count;
        const xyz = new Float32Array(3 * n);
        const w = new Float32Array(n);
        for (let i = 0; i < n; i++) {
          xyz[3 * i] = tangent.getX(i);
          xyz[3 * i + 1] = tangent.getY(i);
          xyz[3 * i + 2] = tangent.getZ(i);
          w[i] = tangent.itemSize > 3 ? (tangent.getW(i) < 0 ? -1 : 1) : 1;
        }
        this.tangentRig = gcs.createRig({ ...input, normals: xyz });
        this.tangentW = w;
      }
    } catch (e) {
      this.rig.dispose();
      throw e;
    }
    this.skin = new Float32Array(this.rig.jointCount * 16);
    ({ pivots: this.pivots, own: this.ownBalls, near: this.nearBalls } = this.boneBounds(input));
    this.balls = this.ownBalls;
    this.scope = commonAncestor([source, ...source.skeleton.bones]);

    this.baseMaterial = options.material ?? source.material;
    this.kit = options.gpuKit ?? glslKit;
    this.warned = options.warned ?? new Set();
    const mesh = new DeformedMesh(new THREE.BufferGeometry(), this.baseMaterial);
    mesh.exactBounds = () => this.exactBounds();
    mesh.onBeforeRender = (renderer, _scene, _camera, geometry, material) => {
      if (this.gpu) this.checkRenderer(renderer, geometry, material);
    };
    mesh.name = source.name;
    mesh.castShadow = source.castShadow;
    mesh.receiveShadow = source.receiveShadow;
    mesh.layers.mask = source.layers.mask;
    mesh.renderOrder = source.renderOrder;
    mesh.customDepthMaterial = source.customDepthMaterial;
    mesh.customDistanceMaterial = source.customDistanceMaterial;
    mesh.frustumCulled = true; // with bounds that follow the animation (update())
    mesh.matrixAutoUpdate = false; // update() copies the source's matrix
    this.mesh = mesh;
    this.sourceLayers = source.layers.mask;
    this.childOfSource = this.inPlace && !source.parent;
    try {
      this.commit(this.prepare(this.method, options));
    } catch (e) {
      this.tangentRig?.dispose();
      this.rig.dispose();
      throw e;
    }
    if (this.inPlace) {
      if (this.childOfSource) {
        source.add(mesh);
      } else {
        const parent = source.parent!;
        parent.add(mesh);
        // Right after the source: PropertyBinding finds nodes by name depth first, so animation
        // tracks (bones, morph influences) keep binding to the source, which has the same name.
        const c = parent.children;
        c.splice(c.indexOf(mesh), 1);
        c.splice(c.indexOf(source) + 1, 0, mesh);
      }
      source.layers.disableAll(); // out of render, shadows and raycasts; children unaffected
      this.update();
    }
  }

  /**
   * Per joint carrying skin: b_j (the joint's bind position, mesh space) and r_j = max |v − b_j|
   * over the vertices weighted to j ('own'); 'near' also counts, for each joint, the vertices of
   * its parent and child joints (the paper's criteria and the classic model move a part's skin
   * with its neighbours' transforms). Why this bounds the deformed mesh: see update().
   */
  private boneBounds(input: RigInput): { pivots: Float32Array; own: BoneBalls; near: BoneBalls } {
    const J = this.rig.jointCount;
    const pivots = new Float32Array(3 * J);
    const m = new THREE.Matrix4();
    for (let j = 0; j < J; j++) {
      m.fromArray(input.inverseBindMatrices as ArrayLike<number> as number[], 16 * j).invert();
      pivots[3 * j] = m.elements[12];
      pivots[3 * j + 1] = m.elements[13];
      pivots[3 * j + 2] = m.elements[14];
    }
    const neighbours: number[][] = Array.from({ length: J }, () => []);
    for (let j = 0; j < J; j++) {
      const p = input.parents[j];
      if (p >= 0 && p < J) { neighbours[j].push(p); neighbours[p].push(j); }
    }
    const own = new Float64Array(J).fill(-1), near = new Float64Array(J).fill(-1);
    const P = input.positions, Jt = input.joints, W = input.weights, K = input.influences ?? 4;
    const n = P.length / 3;
    const reach = (r2: Float64Array, j: number, v: number) => {
      const dx = P[3 * v] - pivots[3 * j], dy = P[3 * v + 1] - pivots[3 * j + 1], dz = P[3 * v + 2] - pivots[3 * j + 2];
      const d = dx * dx + dy * dy + dz * dz;
      if (d > r2[j]) r2[j] = d;
    };
    for (let v = 0; v < n; v++) {
      for (let k = 0; k < K; k++) {
        if (!(W[K * v + k] > 0)) continue;
        const j = Jt[K * v + k];
        if (j >= J) continue;
        reach(own, j, v);
        reach(near, j, v);
        for (const q of neighbours[j]) reach(near, q, v);
      }
    }
    const balls = (r2: Float64Array): BoneBalls => {
      const joints: number[] = [];
      const radii = new Float32Array(J);
      for (let j = 0; j < J; j++) if (r2[j] >= 0) { joints.push(j); radii[j] = Math.sqrt(r2[j]) * (1 + 1e-6); }
      return { joints: Uint32Array.from(joints), radii };
    };
    return { pivots, own: balls(own), near: balls(near) };
  }

  /** Rebuilds the deformer (e.g. a new section count, another backend); the geometry is replaced, `mesh` stays. */
  rebuild(method: DeformerKind = this.method, options: RebuildOptions = {}): void {
    this.live();
    // Build first: if it throws, the current deformer and geometry stay as they were.
    this.commit(this.prepare(method, options));
  }

  /** @internal Builds the next deformer and its geometry without showing them. */
  prepare(method: DeformerKind, options: RebuildOptions = {}): PendingBuild {
    const gcsOptions = { ...this.options.gcs, ...options.gcs };
    const classicOptions = { ...this.options.classic, ...options.classic };
    const backend = options.backend ?? this.options.backend ?? 'cpu';
    if (backend !== 'cpu' && backend !== 'gpu') throw new GcsError('INVALID_ARGUMENT', `backend must be 'cpu' or 'gpu'; got '${String(backend)}'`);
    const note = backend === 'gpu' ? this.gpuUnsupported(method) : '';
    const onGpu = backend === 'gpu' && !note;
    const gpuPath = options.gpuPath ?? this.options.gpuPath ?? 'auto';
    if (gpuPath !== 'auto' && gpuPath !== 'joints' && gpuPath !== 'sections')
      throw new GcsError('INVALID_ARGUMENT', `gpuPath must be 'auto', 'joints' or 'sections'; got '${String(gpuPath)}'`);
    const build = (rig: Rig) => method === 'gcs' ? rig.buildGcs(gcsOptions)
      : method === 'classic' ? rig.buildClassic(classicOptions) : rig.build(method);
    const deformer = build(this.rig);
    let tangentDeformer: Deformer | null = null;
    let gpu: GpuBuild | null = null;
    try {
      const sourceVertex = deformer.sourceVertex;
      const morph = method === 'classic' ? null : morphData(this.source.geometry);
      if (morph) deformer.setMorphTargets(morph.positions, morph.normals);
      if (onGpu) {
        gpu = this.prepareGpu(deformer as GcsDeformer, gpuPath === 'auto' ? undefined : gpuPath);
        const geometry = this.makeGeometry(deformer, sourceVertex, null, gpu);
        return { method, gcs: gcsOptions, classic: classicOptions, deformer, tangentDeformer, geometry, maxDelta: morph?.maxDelta ?? null, gpu, note, backend, gpuPath };
      }
      if (this.tangentRig && sourceVertex) {
        tangentDeformer = build(this.tangentRig);
        // Same positions and weights, so the same vertex order; checked, not assumed.
        const order = tangentDeformer.sourceVertex;
        if (!order || order.length !== sourceVertex.length || order.some((v, i) => v !== sourceVertex[i])) {
          tangentDeformer.dispose();
          tangentDeformer = null;
        }
      }
      const geometry = this.makeGeometry(deformer, sourceVertex, tangentDeformer, null);
      return { method, gcs: gcsOptions, classic: classicOptions, deformer, tangentDeformer, geometry, maxDelta: morph?.maxDelta ?? null, gpu: null, note, backend, gpuPath };
    } catch (e) {
      if (gpu) disposeGpu(gpu);
      tangentDeformer?.dispose();
      deformer.dispose();
      throw e;
    }
  }

  /** Why this build cannot run on the GPU, or ''. */
  private gpuUnsupported(method: DeformerKind): string {
    if (method !== 'gcs') return `the GPU backend runs GCS; '${method}' runs on the CPU`;
    for (const m of Array.isArray(this.baseMaterial) ? this.baseMaterial : [this.baseMaterial]) {
      const reason = this.kit.support(m);
      if (reason) return reason;
    }
    return '';
  }

  /**
   * At each draw of a GPU build: a renderer that cannot run this kit's materials (WebGPURenderer
   * never runs the GLSL patch; WebGLRenderer without a nodes handler cannot draw node materials)
   * would draw the bind pose or nothing. Instead this draw is skipped, the skin moves to the CPU
   * backend (backendNote says why) and one console warning says so; the next frame is right.
   */
  private checkRenderer(renderer: unknown, geometry: THREE.BufferGeometry, material: THREE.Material): void {
    const why = this.kit.mismatch(renderer, material);
    if (!why) return;
    geometry.setDrawRange(0, 0); // this draw: nothing rather than the bind pose
    const next = this.prepare(this.method, { backend: 'cpu' });
    next.note = why;
    this.commit(next, true); // the old geometry is being drawn: freed at the next update()
  }

  /** The per-frame texture (joint poses or section transforms) and the GCS materials of a GPU build. */
  private prepareGpu(deformer: GcsDeformer, path?: GpuPath): GpuBuild {
    const sections = new GpuSections(deformer, 1, 2048, path);
    const materials = this.kit.build(this.baseMaterial, sections, null);
    const raycast = new THREE.BufferGeometry();
    raycast.setIndex(new THREE.BufferAttribute(deformer.indices, 1));
    raycast.setAttribute('position', new THREE.BufferAttribute(deformer.positions, 3));
    raycast.boundingBox = this.box;
    raycast.boundingSphere = this.sphere;
    return { sections, materials, raycast };
  }

  /** @internal Shows a prepared build; the previous deformer and geometry are freed (the geometry at the next update() when `duringDraw`). */
  commit(next: PendingBuild, duringDraw = false): void {
    this.deformer?.dispose();
    this.tangentDeformer?.dispose();
    if (this.gpu) disposeGpu(this.gpu);
    this.gpu = next.gpu;
    this.note = next.note;
    if (next.note && !this.warned.has(next.note)) {
      this.warned.add(next.note);
      console.warn(`gcs-skin: ${next.note}. This skin runs on the CPU backend.`);
    }
    const mesh = this.mesh as DeformedMesh;
    const gpuMaterials = next.gpu?.materials;
    mesh.material = gpuMaterials ? gpuMaterials.material : this.baseMaterial;
    // Node materials cast their shadows through their own position node: no custom depth material.
    mesh.customDepthMaterial = gpuMaterials ? gpuMaterials.depth ?? undefined : this.source.customDepthMaterial;
    mesh.customDistanceMaterial = gpuMaterials ? gpuMaterials.distance ?? undefined : this.source.customDistanceMaterial;
    mesh.raycastGeometry = next.gpu ? next.gpu.raycast : null;
    // GPU: three.js applies the morph targets in the shader, from the source's influences (the same array).
    const gpuMorphs = next.gpu && next.geometry.morphAttributes.position;
    mesh.morphTargetInfluences = gpuMorphs ? this.source.morphTargetInfluences : undefined;
    mesh.morphTargetDictionary = gpuMorphs ? this.source.morphTargetDictionary : undefined;
    this.deformer = next.deformer;
    this.tangentDeformer = next.tangentDeformer;
    this.tangentOut = next.tangentDeformer ? (next.geometry.getAttribute('tangent') as THREE.BufferAttribute).array as Float32Array : null;
    this.maxDelta = next.maxDelta;
    const paper = next.method === 'gcs' && (next.gcs.criterion === 'y' || next.gcs.criterion === 'axial');
    this.balls = paper || next.method === 'classic' ? this.nearBalls : this.ownBalls;
    this.ballFactor = next.method === 'classic' ? 1 + CLASSIC_LIMITS.maxBulge : 1;
    this.method = next.method;
    this.options = { ...this.options, gcs: next.gcs, classic: next.classic, method: next.method, backend: next.backend, gpuPath: next.gpuPath };
    const old = this.mesh.geometry;
    this.mesh.geometry = next.geometry;
    this.update();
    if (duringDraw) this.retired = old;
    else old.dispose();
  }

  /** @internal Frees a prepared build that will not be shown. */
  discard(next: PendingBuild): void {
    if (next.gpu) disposeGpu(next.gpu);
    next.tangentDeformer?.dispose();
    next.deformer.dispose();
    next.geometry.dispose();
  }

  private makeGeometry(deformer: Deformer, sourceVertex: Uint32Array | null, tangentDeformer: Deformer | null, gpu: GpuBuild | null): THREE.BufferGeometry {
    const src = this.source.geometry;
    const indices = deformer.indices;
    let geometry: THREE.BufferGeometry;
    if (gpu) {
      // The bind pose, uploaded once, with the section data; three.js morphs in the shader, before GCS.
      geometry = bindGeometry(deformer as GcsDeformer, this.rig.jointCount, src, { tangents: this.options.tangents !== 'drop', morphs: true });
    } else {
      geometry = new THREE.BufferGeometry();
      geometry.setIndex(new THREE.BufferAttribute(indices, 1));
      geometry.setAttribute('position', new THREE.BufferAttribute(deformer.positions, 3).setUsage(THREE.DynamicDrawUsage));
      geometry.setAttribute('normal', new THREE.BufferAttribute(deformer.normals, 3).setUsage(THREE.DynamicDrawUsage));
      if (sourceVertex) {
        for (const [name, attr] of Object.entries(src.attributes))
          if (!SKINNING_ATTRIBUTES.has(name)) geometry.setAttribute(name, remapAttribute(attr, sourceVertex));
        if (tangentDeformer && this.tangentW) {
          const w = new Float32Array(4 * sourceVertex.length);
          for (let o = 0; o < sourceVertex.length; o++) w[4 * o + 3] = this.tangentW[sourceVertex[o]];
          geometry.setAttribute('tangent', new THREE.BufferAttribute(w, 4).setUsage(THREE.DynamicDrawUsage));
        }
      } else if (deformer instanceof ClassicDeformer) {
        // Resampled: the source's uv, colours and custom attributes from the closest source point.
        deformer.deform(identitySkin(this.rig.jointCount));
        transferSurfaceAttributes(src, geometry, deformer.positions, deformer.sourceOfVertex, SKINNING_ATTRIBUTES);
      }
    }
    // Groups (multi-material) and the draw range count index entries: they carry over when the
    // deformer kept the triangles in order (GCS, LBS, DQS remap vertex ids only; checked here).
    let sameOrder = !!sourceVertex;
    if (sourceVertex) {
      const srcIndex = src.index;
      for (let i = 0; i < indices.length && sameOrder; i++)
        sameOrder = sourceVertex[indices[i]] === (srcIndex ? srcIndex.getX(i) : i);
      if (srcIndex && indices.length !== srcIndex.count) sameOrder = false;
    }
    if (sameOrder) {
      for (const g of src.groups) geometry.addGroup(g.start, g.count, g.materialIndex);
      geometry.setDrawRange(src.drawRange.start, src.drawRange.count);
    } else if (Array.isArray(this.mesh.material)) {
      geometry.addGroup(0, Infinity, 0); // resampled triangles: the first material for all
    }
    geometry.boundingBox = this.box;
    geometry.boundingSphere = this.sphere;
    return geometry;
  }

  /**
   * Poses from the skeleton and deforms. Call once per frame, after the mixer. By default it
   * first updates the world matrices of the smallest subtree holding the source and its bones
   * (and of their ancestors); pass `{ updateMatrixWorld: false }` when the caller has already
   * done that this frame (GcsCharacter does, once for all its skins). In place, an invisible
   * source (`source.visible === false`) hides the mesh and skips the deform.
   *
   * Bounds for frustum culling, per frame from the bones rather than the output (a JavaScript
   * pass over 17 k output vertices costs about as much as the wasm deform itself; this is
   * O(joints)): each joint j's posed position p_j = S_j b_j and a ball of radius
   * s_j·(k·r_j + Σ|w_t|·maxDelta_t) (s_j the largest axis scale of S_j, w_t the morph
   * influences, b_j and r_j from boneBounds()). LBS moves a vertex to a convex combination of
   * the S_j v, each in its joint's ball, so the box of the balls always holds it. GCS (weights)
   * and DQS blend rigid motions of the vertex's own joints: where those agree at a joint (a
   * connected skeleton) the blend turns about it, so the vertex stays within r_j of that posed
   * joint. The paper's criteria also move a part's skin with its parent's and child's motions,
   * so they use the 'near' radii; the classic model's contours swell by at most 1 + bulge, so
   * it uses the 'near' radii times k = 1 + maxBulge (k = 1 otherwise). Checked on 30 frames of
   * every clip of the default human and the shared test characters (CesiumMan, Fox,
   * RobotExpressive, Soldier), every method and criterion: every vertex inside. The sphere
   * circumscribes the box (generous: culling must never drop a visible mesh; a whole body's
   * sphere came out 1.2–1.5× the exact one, classic about 5×). Raycasts get exact bounds
   * instead (DeformedMesh). No allocation: matrices, vectors and bounds are preallocated.
   */
  update(options?: { updateMatrixWorld?: boolean }): void {
    this.live();
    if (this.retired) {
      this.retired.dispose();
      this.retired = null;
    }
    const source = this.source;
    const mesh = this.mesh;
    if (options?.updateMatrixWorld !== false) updateWorld(this.scope);
    if (this.inPlace) {
      mesh.visible = source.visible;
      if (!source.visible) return;
    }
    const skin = this.skin;
    writeSkinMatrices(source, skin, 0, this.tmp);
    const deformer = this.deformer;
    const gpu = this.gpu;
    let grow = 0; // how far the morphs can move a vertex this frame
    const maxDelta = this.maxDelta;
    if (maxDelta) {
      const influences = source.morphTargetInfluences;
      if (influences && influences.length === maxDelta.length) {
        if (!gpu) deformer.setMorphInfluences(influences); // the GPU backend morphs in the shader
        for (let t = 0; t < influences.length; t++) grow += Math.abs(influences[t]) * maxDelta[t];
      }
    }
    if (gpu) {
      gpu.sections.skins.set(skin);
      gpu.sections.update(); // section transforms only; the texture is uploaded at the next render
      this.cpuFresh = false;
    } else {
      deformer.deform(skin);
    }
    this.boundsFromBones(grow);
    const tangents = this.tangentDeformer;
    if (tangents) {
      tangents.deform(skin);
      const t = tangents.normals, out = this.tangentOut!;
      for (let o = 0, n = tangents.vertexCount; o < n; o++) {
        out[4 * o] = t[3 * o];
        out[4 * o + 1] = t[3 * o + 1];
        out[4 * o + 2] = t[3 * o + 2];
      }
      (mesh.geometry.getAttribute('tangent') as THREE.BufferAttribute).needsUpdate = true;
    }
    if (this.inPlace && !this.childOfSource) {
      mesh.position.copy(source.position);
      mesh.quaternion.copy(source.quaternion);
      mesh.scale.copy(source.scale);
      mesh.matrix.copy(source.matrix);
      mesh.matrixWorld.copy(source.matrixWorld);
    } else if (this.childOfSource) {
      mesh.matrixWorld.copy(source.matrixWorld); // matrix stays identity
    } else {
      mesh.matrix.copy(source.matrixWorld);
      mesh.matrixWorld.copy(source.matrixWorld);
    }
    if (!gpu) this.syncAttributes();
  }

  /** The per-frame bounds (see update()), from the skin matrices just computed. */
  private boundsFromBones(grow: number): void {
    const skin = this.skin, tmp = this.tmp, p = this.point, pivots = this.pivots;
    const { joints, radii } = this.balls, factor = this.ballFactor;
    let x0 = Infinity, y0 = Infinity, z0 = Infinity, x1 = -Infinity, y1 = -Infinity, z1 = -Infinity;
    for (let i = 0; i < joints.length; i++) {
      const j = joints[i];
      tmp.fromArray(skin, 16 * j);
      p.set(pivots[3 * j], pivots[3 * j + 1], pivots[3 * j + 2]).applyMatrix4(tmp);
      const r = (radii[j] * factor + grow) * tmp.getMaxScaleOnAxis();
      if (p.x - r < x0) x0 = p.x - r;
      if (p.y - r < y0) y0 = p.y - r;
      if (p.z - r < z0) z0 = p.z - r;
      if (p.x + r > x1) x1 = p.x + r;
      if (p.y + r > y1) y1 = p.y + r;
      if (p.z + r > z1) z1 = p.z + r;
    }
    this.setBounds(x0, y0, z0, x1, y1, z1);
    this.exactFresh = false;
  }

  private setBounds(x0: number, y0: number, z0: number, x1: number, y1: number, z1: number): void {
    if (!(x0 <= x1 && y0 <= y1 && z0 <= z1)) {
      this.box.makeEmpty();
      this.sphere.makeEmpty();
      return;
    }
    this.box.min.set(x0, y0, z0);
    this.box.max.set(x1, y1, z1);
    this.box.getCenter(this.sphere.center);
    this.sphere.radius = 0.5 * Math.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2);
  }

  /** Exact bounds of the current output (one pass), before raycasts; false when the output is stale. */
  private exactBounds(): boolean {
    if (this.isDisposed || (this.inPlace && !this.mesh.visible)) return false;
    if (this.exactFresh) return true;
    const gpu = this.gpu;
    if (gpu && !this.cpuFresh) {
      // GPU backend: the vertices exist only in the shader; deform on the CPU for this raycast.
      const influences = this.source.morphTargetInfluences;
      if (this.maxDelta && influences && influences.length === this.maxDelta.length) this.deformer.setMorphInfluences(influences);
      this.deformer.deform(this.skin);
      (gpu.raycast.getAttribute('position') as THREE.BufferAttribute).array = this.deformer.positions;
      this.cpuFresh = true;
    }
    const a = this.deformer.positions;
    let x0 = Infinity, y0 = Infinity, z0 = Infinity, x1 = -Infinity, y1 = -Infinity, z1 = -Infinity;
    for (let i = 0; i < a.length; i += 3) {
      const x = a[i], y = a[i + 1], z = a[i + 2];
      x0 = x < x0 ? x : x0; x1 = x > x1 ? x : x1;
      y0 = y < y0 ? y : y0; y1 = y > y1 ? y : y1;
      z0 = z < z0 ? z : z0; z1 = z > z1 ? z : z1;
    }
    this.setBounds(x0, y0, z0, x1, y1, z1);
    this.exactFresh = true;
    return true;
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

  /** The backend of the current build: 'gpu' only when asked for and possible (see backendNote). */
  get backend(): Backend {
    return this.gpu ? 'gpu' : 'cpu';
  }

  /** Why the GPU backend was asked for and the CPU runs ('' otherwise). */
  get backendNote(): string {
    return this.note;
  }

  /** GPU backend: the per-frame texels (joint poses or section transforms) and their texture (null on the CPU backend). */
  get gpuSections(): GpuSections | null {
    return this.gpu?.sections ?? null;
  }

  /** GPU backend: the path of the current build ('joints' or 'sections'); null on the CPU backend. */
  get gpuPath(): GpuPath | null {
    return this.gpu?.sections.path ?? null;
  }

  /** Bytes this skin sends to the GPU per update(): the vertex buffers (CPU backend) or the section texture (GPU backend). */
  get bytesPerFrame(): number {
    if (this.gpu) return this.gpu.sections.bytesPerUpdate;
    let bytes = 0;
    for (const name of ['position', 'normal', 'tangent']) {
      const a = this.mesh.geometry.getAttribute(name) as THREE.BufferAttribute | undefined;
      if (a && a.usage === THREE.DynamicDrawUsage) bytes += a.array.byteLength;
    }
    return bytes;
  }

  /** True when tangents are deformed this build (the source has them and the method keeps vertices). */
  get deformsTangents(): boolean {
    return this.tangentDeformer !== null;
  }

  private live(): void {
    if (this.isDisposed) throw new GcsError('DISPOSED', 'this SkinDeformer has been disposed');
  }

  /**
   * Frees the wasm memory (deformers and rigs) and the output geometry, removes `mesh` from its
   * parent and, in place, puts the source back in the render (its layers as they were). Not the
   * material, which is the source's or the caller's. Safe to call twice.
   */
  dispose(): void {
    if (this.isDisposed) return;
    this.isDisposed = true;
    this.deformer?.dispose();
    this.tangentDeformer?.dispose();
    this.tangentDeformer = null;
    if (this.gpu) disposeGpu(this.gpu);
    this.gpu = null;
    const mesh = this.mesh as DeformedMesh;
    mesh.raycastGeometry = null;
    this.tangentRig?.dispose();
    this.rig.dispose();
    this.mesh.removeFromParent();
    this.mesh.geometry.dispose();
    (this.mesh as DeformedMesh).exactBounds = null;
    if (this.inPlace) this.source.layers.mask = this.sourceLayers;
  }

  get disposed(): boolean {
    return this.isDisposed;
  }
}

export interface GcsCharacterOptions {
  /** Which deformer drives every skin. Default 'gcs'. */
  method?: DeformerKind;
  gcs?: GcsOptions;
  classic?: ClassicOptions;
  /** See SkinDeformerOptions.tangents. Default 'deform'. */
  tangents?: 'deform' | 'drop';
  /** Which SkinnedMeshes under the root to drive. Default: all of them. */
  filter?: (mesh: THREE.SkinnedMesh) => boolean;
  /** See SkinDeformerOptions.backend: 'cpu' (default) or 'gpu' (GCS section transforms in the vertex shader). */
  backend?: Backend;
  /** See SkinDeformerOptions.gpuPath. Default 'auto'. */
  gpuPath?: GpuPath | 'auto';
  /** @internal See SkinDeformerOptions.gpuKit. */
  gpuKit?: GpuMaterialKit;
}

/**
 * A whole character deformed in wasm, in place: every SkinnedMesh under `root` (a glTF scene or
 * any Object3D, several skins on one or several skeletons) gets a deformed THREE.Mesh under the
 * same parent with the same local transform, material (the same object: textures, vertex
 * colours, normal maps), attributes, shadow flags, name, layers and renderOrder; the SkinnedMesh
 * leaves the render, shadows and raycasts (its layers are cleared) but stays in the graph, so the
 * mixer keeps driving its bones and morph influences. Adding `root` to your scene is all it
 * takes. Morph targets: GCS, LBS and DQS (the classic model resamples the mesh and skips them).
 *
 *   const character = new GcsCharacter(gcs, gltf.scene, { method: 'gcs', gcs: { sections: 8 } });
 *   // each frame: mixer.update(dt); character.update(); renderer.render(scene, camera);
 *
 * `dispose()` frees every skin's wasm memory and deformed geometry, removes the deformed meshes
 * and shows the SkinnedMeshes again. Throws GcsError 'NO_SKIN' if root holds no SkinnedMesh; a
 * skin that cannot be built (GcsError) undoes the ones already built.
 */
export class GcsCharacter {
  readonly root: THREE.Object3D;
  /** One per SkinnedMesh, in traversal order. */
  readonly skins: readonly SkinDeformer[];
  /** The deformed meshes, in the order of `skins`. */
  readonly meshes: readonly THREE.Mesh[];
  /** What update() refreshes: root, or a common ancestor of root and bones kept outside it. */
  private readonly scope: THREE.Object3D;
  private isDisposed = false;

  constructor(readonly gcs: GcsSkin, root: THREE.Object3D, options: GcsCharacterOptions = {}) {
    if (!root || !(root as THREE.Object3D).isObject3D) throw new GcsError('INVALID_ARGUMENT', 'GcsCharacter needs a THREE.Object3D (a glTF scene, a group or a SkinnedMesh)');
    this.root = root;
    const sources: THREE.SkinnedMesh[] = [];
    root.traverse((o) => {
      const s = o as THREE.SkinnedMesh;
      if (s.isSkinnedMesh && (!options.filter || options.filter(s))) sources.push(s);
    });
    if (!sources.length) throw new GcsError('NO_SKIN', 'no skinned mesh (THREE.SkinnedMesh with a skeleton) under this object: there is nothing to deform');
    updateWorld(root);
    const skins: SkinDeformer[] = [];
    const warned = new Set<string>();
    try {
      for (const source of sources) {
        skins.push(new SkinDeformer(gcs, source, {
          method: options.method, gcs: options.gcs, classic: options.classic, tangents: options.tangents, inPlace: true,
          backend: options.backend, gpuPath: options.gpuPath, gpuKit: options.gpuKit, warned,
        }));
      }
    } catch (e) {
      for (const s of skins.reverse()) s.dispose();
      throw e;
    }
    this.skins = skins;
    this.meshes = skins.map((s) => s.mesh);
    this.scope = commonAncestor([root, ...sources.flatMap((s) => s.skeleton.bones)]);
  }

  /**
   * Once per frame, after the mixer: one world-matrix update of the character (ancestors first),
   * then every skin poses from its skeleton and deforms. No allocation.
   */
  update(): void {
    if (this.isDisposed) throw new GcsError('DISPOSED', 'this GcsCharacter has been disposed');
    updateWorld(this.scope);
    const skins = this.skins;
    for (let i = 0; i < skins.length; i++) skins[i].update(NO_WORLD_UPDATE);
  }

  /**
   * Rebuilds every skin with another method or options (e.g. a new section count). All or
   * nothing: every new deformer is built before any is shown; on a failure all stay as they were.
   */
  rebuild(method: DeformerKind = this.method, options: RebuildOptions = {}): void {
    if (this.isDisposed) throw new GcsError('DISPOSED', 'this GcsCharacter has been disposed');
    const pending: { skin: SkinDeformer; build: PendingBuild }[] = [];
    try {
      for (const skin of this.skins) pending.push({ skin, build: skin.prepare(method, options) });
    } catch (e) {
      for (const p of pending) p.skin.discard(p.build);
      throw e;
    }
    for (const p of pending) p.skin.commit(p.build);
  }

  /** The method of the current build. */
  get method(): DeformerKind {
    return this.skins[0].currentMethod;
  }

  /** 'gpu' when every skin runs on the GPU backend, else 'cpu' (see each skin's backendNote). */
  get backend(): Backend {
    return this.skins.every((s) => s.backend === 'gpu') ? 'gpu' : 'cpu';
  }

  /** Frees every skin (wasm memory, deformed geometry), removes the deformed meshes and shows the SkinnedMeshes again. Safe to call twice. */
  dispose(): void {
    if (this.isDisposed) return;
    this.isDisposed = true;
    for (const s of this.skins) s.dispose();
  }

  get disposed(): boolean {
    return this.isDisposed;
  }
}

const NO_WORLD_UPDATE = Object.freeze({ updateMatrixWorld: false });

/** Frees a GPU build: its wasm buffers, texture, GCS materials and raycast geometry. */
function disposeGpu(gpu: GpuBuild): void {
  gpu.sections.dispose();
  disposeGpuMaterials(gpu.materials);
  gpu.raycast.dispose();
}
