// One SkinnedMesh deformed in wasm: its lifecycle (build, rebuild, dispose), its placement in the
// scene and its per-frame update (pose, deform, bounds). The builds themselves are build.ts's.
import * as THREE from 'three';
import { GcsError } from '../errors.js';
import { CLASSIC_LIMITS, type Deformer, type DeformerKind, type GcsSkin, type Rig } from '../index.js';
import type { GpuMaterialKit } from '../gpu/kit.js';
import { PREVIOUS_POSITION_ATTRIBUTE, type GpuPath } from '../gpu/layout.js';
import type { GpuSections } from '../gpu/sections.js';
import { glslKit } from '../gpu/webgl-materials.js';
import { boneBounds, boundsFromBones, boundsOfPositions, type BoneBalls } from './bounds.js';
import { discardBuild, disposeGpu, prepareBuild, type GpuBuild, type PendingBuild } from './build.js';
import { checkGcsSkin } from './check-gcs.js';
import { DeformedMesh } from './deformed-mesh.js';
import { keepAttributeLive } from './live-views.js';
import type { Backend, RebuildOptions, SkinDeformerOptions } from './options.js';
import { rigInputFromSkinnedMesh } from './rig-input.js';
import { commonAncestor, updateWorld } from './scene-graph.js';
import type { SkeletonPoses } from './skeleton-poses.js';
import { writeSkinMatrices } from './skin-matrices.js';

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
 *
 * @example
 * ```ts
 * const skin = new SkinDeformer(gcs, skinnedMesh, { method: 'gcs', inPlace: true });
 * // each frame, after the mixer: skin.update();
 * skin.rebuild('gcs', { gcs: { sections: 12 } });
 * skin.dispose();
 * ```
 */
export class SkinDeformer {
  /** The skinned mesh whose skeleton drives this one (only read; in place, it leaves the render). */
  readonly source: THREE.SkinnedMesh;
  /** The rig read from the source (owned by this SkinDeformer). */
  readonly rig: Rig;
  /** The deformed mesh that is drawn: its attributes are views on wasm memory (CPU backend). */
  readonly mesh: THREE.Mesh;
  /** The current deformer (replaced by `rebuild`). */
  deformer!: Deformer;
  private method: DeformerKind;
  private options: SkinDeformerOptions;
  private readonly skin: Float32Array;
  private readonly tmp = new THREE.Matrix4();
  /** What update() refreshes: the lowest common ancestor of the source and its bones. */
  private readonly scope: THREE.Object3D;
  private readonly inPlace: boolean;
  /** In place: the source's layers mask, given back by dispose(). */
  private readonly sourceLayers: number;
  /** In place, parentless source: the mesh is its child at identity. */
  private readonly childOfSource: boolean;
  /** The source's tangents (xyz, w per source vertex) that CPU builds hand their deformer; null without or 'drop'. */
  private readonly tangents: Float32Array | null = null;
  /**
   * CPU backend, velocity: set when the renderer drew a velocity pass (kit.drawsVelocity); from the
   * next update() the deformer keeps its previous positions and the mesh wears the kit's velocity
   * material. 'unsupported': the kit or a material cannot (drawn as before, no velocity).
   */
  private velocity: 'off' | 'wanted' | 'unsupported' | { material: THREE.Material | THREE.Material[] } = 'off';
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

  /**
   * @param gcs The core (`await initGcsSkin()`).
   * @param source The SkinnedMesh to deform; its geometry and skeleton are read, not changed.
   * @param options Method, model options, material, placement, tangents, backend.
   * @throws GcsError `NO_SKIN` when `source` is not a skinned mesh with a skeleton, and the rig's and the
   * build's codes (`LENGTH_MISMATCH`, `BAD_WEIGHTS`, `SECTION_COUNT`, `OUT_OF_MEMORY`, …).
   */
  constructor(readonly gcs: GcsSkin, source: THREE.SkinnedMesh, options: SkinDeformerOptions = {}) {
    checkGcsSkin(gcs, 'SkinDeformer');
    const input = rigInputFromSkinnedMesh(source);
    this.source = source;
    this.options = { ...options };
    this.method = options.method ?? 'gcs';
    this.inPlace = options.inPlace === true;
    this.rig = gcs.createRig(input);
    const tangent = source.geometry.getAttribute('tangent');
    if (tangent && tangent.itemSize >= 3 && options.tangents !== 'drop') {
      const n = tangent.count, t = new Float32Array(4 * n);
      // Build time only: getX/getY… read interleaved and normalised attributes alike.
      for (let i = 0; i < n; i++)
        t.set([tangent.getX(i), tangent.getY(i), tangent.getZ(i), tangent.itemSize > 3 && tangent.getW(i) < 0 ? -1 : 1], 4 * i);
      this.tangents = t;
    }
    this.skin = new Float32Array(this.rig.jointCount * 16);
    ({ pivots: this.pivots, own: this.ownBalls, near: this.nearBalls } = boneBounds(input, this.rig.jointCount));
    this.balls = this.ownBalls;
    this.scope = commonAncestor([source, ...source.skeleton.bones]);

    this.baseMaterial = options.material ?? source.material;
    this.kit = options.gpuKit ?? glslKit;
    this.warned = options.warned ?? new Set();
    const mesh = new DeformedMesh(new THREE.BufferGeometry(), this.baseMaterial);
    mesh.exactBounds = () => this.exactBounds();
    mesh.onBeforeRender = (renderer, _scene, _camera, geometry, material) => {
      if (this.gpu) this.checkRenderer(renderer, geometry, material);
      else if (this.velocity === 'off' && this.kit.drawsVelocity(renderer)) this.velocity = 'wanted';
    };
    // Shadow maps are drawn before the scene: the GPU backend's once-per-frame work runs at the first of either.
    mesh.onBeforeShadow = (renderer, _object, _camera, _shadowCamera, geometry, material) => {
      if (this.gpu) this.checkRenderer(renderer, geometry, material);
    };
    // A GPU material whose shader failed to compile drew nothing: the next frame runs on the CPU backend.
    mesh.onAfterRender = (renderer, _scene, _camera, _geometry, material) => {
      if (this.gpu) this.checkCompiled(renderer, material);
    };
    mesh.onAfterShadow = (renderer, _object, _camera, _shadowCamera, _geometry, material) => {
      if (this.gpu) this.checkCompiled(renderer, material);
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

  /** Rebuilds the deformer (e.g. a new section count, another backend); the geometry is replaced, `mesh` stays. */
  rebuild(method: DeformerKind = this.method, options: RebuildOptions = {}): void {
    this.live();
    // Build first: if it throws, the current deformer and geometry stay as they were.
    this.commit(this.prepare(method, options));
  }

  /** @internal Builds the next deformer and its geometry without showing them. */
  prepare(method: DeformerKind, options: RebuildOptions = {}): PendingBuild {
    return prepareBuild({
      source: this.source, rig: this.rig, tangents: this.tangents, options: this.options,
      baseMaterial: this.baseMaterial, kit: this.kit, mesh: this.mesh, box: this.box, sphere: this.sphere,
    }, method, options);
  }

  /**
   * At each draw of a GPU build: a renderer that cannot run this kit's materials (WebGPURenderer
   * never runs the GLSL patch; WebGLRenderer without a nodes handler cannot draw node materials)
   * would draw the bind pose or nothing. Instead this draw is skipped, the skin moves to the CPU
   * backend (backendNote says why) and one console warning says so; the next frame is right.
   */
  private checkRenderer(renderer: unknown, geometry: THREE.BufferGeometry, material: THREE.Material): void {
    const why = this.kit.mismatch(renderer, material);
    // The joint-level path's node pass (once per frame); a renderer without float targets takes the section-level path.
    const noPass = why ? null : this.gpu!.materials.beforeDraw?.(renderer) ?? null;
    if (!why && !noPass) return;
    geometry.setDrawRange(0, 0); // this draw: nothing rather than the bind pose
    const next = this.prepare(this.method, why ? { backend: 'cpu' } : { gpuPath: 'sections' });
    next.note = why ?? `${noPass}: this skin runs the section-level path (gpuPath 'sections')`;
    this.commit(next, true); // the old geometry is being drawn: freed at the next update()
  }

  /** After a GPU draw: a shader that did not compile moves the skin to the CPU backend (backendNote says why). */
  private checkCompiled(renderer: unknown, material: THREE.Material): void {
    const why = this.gpu!.materials.compileError?.(renderer, material);
    if (!why) return;
    const next = this.prepare(this.method, { backend: 'cpu' });
    next.note = why;
    this.commit(next, true);
  }

  /** @internal Shows a prepared build; the previous deformer and geometry are freed (the geometry at the next update() when `duringDraw`). */
  commit(next: PendingBuild, duringDraw = false): void {
    this.deformer?.dispose();
    if (this.gpu) disposeGpu(this.gpu);
    this.gpu = next.gpu;
    this.stopVelocity(); // a CPU build starts it again at its first update()
    this.note = next.note;
    if (next.note && !this.warned.has(next.note)) {
      this.warned.add(next.note);
      console.warn(`gcs-skin: ${next.note}.${next.gpu ? '' : ' This skin runs on the CPU backend.'}`);
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
    discardBuild(next);
  }

  /**
   * Poses from the skeleton and deforms. Call once per frame, after the mixer. By default it
   * first updates the world matrices of the smallest subtree holding the source and its bones
   * (and of their ancestors); pass `{ updateMatrixWorld: false }` when the caller has already
   * done that this frame (GcsCharacter does, once for all its skins), and `poses` to take the skin
   * matrices from a SkeletonPoses (GcsCharacter's: each skeleton posed once a frame, not once per
   * skin). In place, an invisible
   * source (`source.visible === false`) hides the mesh and skips the deform.
   *
   * Bounds for frustum culling, per frame from the bones rather than the output (a JavaScript
   * pass over 17 k output vertices costs about as much as the wasm deform itself; this is
   * O(joints): bounds.ts says why they hold). Raycasts get exact bounds instead (DeformedMesh).
   * No allocation: matrices, vectors and bounds are preallocated.
   */
  update(options?: { updateMatrixWorld?: boolean; poses?: SkeletonPoses }): void {
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
    if (options?.poses) skin.set(options.poses.skinOf(source)); // posed once for every skin of its skeleton
    else writeSkinMatrices(source, skin, 0, this.tmp);
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
      if (this.velocity === 'wanted') this.startVelocity();
      deformer.deform(skin); // positions, normals and tangents; the last positions become the previous
    }
    boundsFromBones(skin, this.pivots, this.balls, this.ballFactor, grow, this.box, this.sphere);
    this.exactFresh = false;
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
    boundsOfPositions(this.deformer.positions, this.box, this.sphere);
    this.exactFresh = true;
    return true;
  }

  /**
   * Points the attributes at the deformer's live views (memory growth detaches old ones; with
   * velocity, positions and previous positions swap arrays every frame) and flags the upload.
   */
  private syncAttributes(): void {
    const geometry = this.mesh.geometry, deformer = this.deformer;
    sync(geometry.getAttribute('position'), deformer.positions);
    sync(geometry.getAttribute('normal'), deformer.normals);
    sync(geometry.getAttribute('tangent'), deformer.tangents);
    sync(geometry.getAttribute(PREVIOUS_POSITION_ATTRIBUTE), deformer.previousPositions);
  }

  /** CPU backend, the first frame after a velocity pass: previous positions kept and handed to the renderer. */
  private startVelocity(): void {
    const base = Array.isArray(this.baseMaterial) ? this.baseMaterial : [this.baseMaterial];
    const materials = base.map((m) => this.kit.velocityMaterial(m));
    if (materials.some((m) => m === null)) {
      for (const m of materials) m?.dispose();
      this.velocity = 'unsupported'; // a custom shader, a node material with its own position node
      return;
    }
    this.deformer.keepPreviousPositions(true);
    const previous = new THREE.BufferAttribute(this.deformer.previousPositions!, 3).setUsage(THREE.DynamicDrawUsage);
    this.mesh.geometry.setAttribute(PREVIOUS_POSITION_ATTRIBUTE, keepAttributeLive(previous, this.deformer, 'previousPositions'));
    const material = Array.isArray(this.baseMaterial) ? materials as THREE.Material[] : materials[0]!;
    this.mesh.material = material;
    this.velocity = { material };
  }

  /** Back to no velocity (a new build; dispose): the velocity materials freed; once wanted, tried again with the next build. */
  private stopVelocity(): void {
    const v = this.velocity;
    if (v === 'off' || v === 'wanted') return;
    if (v !== 'unsupported') for (const m of Array.isArray(v.material) ? v.material : [v.material]) m.dispose();
    this.velocity = 'wanted';
  }

  /** The method the current deformer runs. */
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
    for (const name of DYNAMIC_ATTRIBUTES) {
      const a = this.mesh.geometry.getAttribute(name) as THREE.BufferAttribute | undefined;
      if (a && a.usage === THREE.DynamicDrawUsage) bytes += a.array.byteLength;
    }
    return bytes;
  }

  /** True when tangents are deformed this build (the source has them and the method keeps vertices: by the core pass, or the GPU backend's shader). */
  get deformsTangents(): boolean {
    return this.gpu ? this.mesh.geometry.getAttribute('tangent') !== undefined : this.deformer.tangents !== null;
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
    this.stopVelocity();
    if (this.gpu) disposeGpu(this.gpu);
    this.gpu = null;
    const mesh = this.mesh as DeformedMesh;
    mesh.raycastGeometry = null;
    this.rig.dispose();
    this.mesh.removeFromParent();
    this.mesh.geometry.dispose();
    (this.mesh as DeformedMesh).exactBounds = null;
    if (this.inPlace) this.source.layers.mask = this.sourceLayers;
  }

  /** Whether `dispose()` has run. */
  get disposed(): boolean {
    return this.isDisposed;
  }
}

/** The CPU backend's attributes uploaded per update() (bytesPerFrame: a list made once, not per call). */
const DYNAMIC_ATTRIBUTES = ['position', 'normal', 'tangent', PREVIOUS_POSITION_ATTRIBUTE] as const;

/** Points a dynamic attribute at `array` (a live wasm view) and flags its upload. */
function sync(attribute: THREE.BufferAttribute | THREE.InterleavedBufferAttribute | undefined, array: Float32Array | null): void {
  const a = attribute as THREE.BufferAttribute | undefined;
  if (!a || !array) return;
  if (a.array !== array) a.array = array;
  a.needsUpdate = true;
}
