/**
 * gcs-skin/crowd: many characters sharing one mesh and one GCS model, each in its own pose, drawn
 * by one THREE.InstancedMesh (one draw call, plus one per shadow pass) whose per-instance section
 * transforms live in one float texture (docs/gpu.md).
 *
 *   const crowd = new GcsCrowd(gcs, skinnedMesh, 200);         // 200 instances of its skin
 *   scene.add(crowd.mesh);
 *   crowd.mesh.setMatrixAt(i, placement);                       // where each one stands
 *   const walk = bakeClip(skinnedMesh, clip);                   // or your own skeletons:
 *   // each frame: crowd.setBakedPose(i, walk, t_i) (or writeSkinMatrices(mesh_i, crowd.skins, crowd.offsetOf(i), tmp)
 *   //             with one reused THREE.Matrix4 `tmp`: without it each call allocates one)
 *   //             crowd.update(); renderer.render(scene, camera);
 *
 * Per frame one wasm call writes every instance's joint poses (the weights criterion, the default:
 * O(instances × joints), 64 bytes per joint) or section transforms ('y' / 'axial', or
 * `gpuPath: 'sections'`: O(instances × sections), 48 bytes per section) into the texture's memory,
 * and three.js uploads it.
 *
 * @module gcs-skin/crowd
 */
import * as THREE from 'three';
import { asGiven, GcsError } from './errors.js';
import type { GcsDeformer, GcsOptions, GcsSkin, Rig } from './index.js';
import { bindGeometry } from './gpu/bind.js';
import { disposeGpuMaterials, type GpuMaterialKit, type GpuMaterials } from './gpu/kit.js';
import type { GpuPath } from './gpu/layout.js';
import { GpuSections } from './gpu/sections.js';
import { glslKit } from './gpu/webgl-materials.js';
import { bakedFrameCount } from './three/bake-limits.js';
import { checkGcsSkin } from './three/check-gcs.js';
import { rigInputFromSkinnedMesh } from './three/rig-input.js';
import { writeSkinMatrices } from './three/skin-matrices.js';

export { writeSkinMatrices } from './three/skin-matrices.js';

/** A clip sampled once into skin matrices: `frames` poses of J × 16 floats, `fps` apart. */
export interface BakedClip {
  /** The clip's name. */
  name: string;
  /** Samples per second. */
  fps: number;
  /** Number of sampled poses. */
  frames: number;
  /** Length in seconds (`frames / fps`). */
  duration: number;
  /** Joints per pose (J). */
  jointCount: number;
  /** frames × J × 16 floats */
  data: Float32Array;
}

/**
 * Samples `clip` on `source`'s skeleton at `fps` (the whole clip, looped) into skin matrices, so
 * that any number of instances can play it at their own time for the cost of a copy. Build time
 * only: it poses the skeleton through a temporary AnimationMixer on `source`'s root and leaves it
 * in the clip's last sampled pose.
 */
export function bakeClip(source: THREE.SkinnedMesh, clip: THREE.AnimationClip, fps = 60): BakedClip {
  if (!source?.isSkinnedMesh || !source.skeleton) throw new GcsError('NO_SKIN', 'bakeClip needs a THREE.SkinnedMesh with a skeleton');
  let root: THREE.Object3D = source;
  while (root.parent) root = root.parent;
  const J = source.skeleton.bones.length;
  const frames = bakedFrameCount(clip, fps, J); // bounds checked before allocating
  const data = new Float32Array(frames * J * 16);
  const mixer = new THREE.AnimationMixer(root);
  const action = mixer.clipAction(clip);
  action.play();
  const tmp = new THREE.Matrix4();
  for (let f = 0; f < frames; f++) {
    mixer.setTime(f / fps);
    root.updateMatrixWorld(true);
    writeSkinMatrices(source, data, f * J * 16, tmp);
  }
  action.stop();
  mixer.uncacheRoot(root);
  return { name: clip.name, fps, frames, duration: frames / fps, jointCount: J, data };
}

/** Options of `GcsCrowd`: the GCS model, the material, the texture width and the GPU path. */
export interface GcsCrowdOptions {
  /** The GCS model (default: the weights criterion, 6 sections, plain). */
  gcs?: GcsOptions;
  /** Drawn with a patched clone of this material. Default: the source's own. */
  material?: THREE.Material | THREE.Material[];
  /** The widest row of the per-frame texture (default 2048, what WebGL2 guarantees). */
  maxTextureWidth?: number;
  /** See SkinDeformerOptions.gpuPath: 'auto' (default: 'joints' for the weights criterion), 'joints' or 'sections'. */
  gpuPath?: GpuPath | 'auto';
  /** @internal How the materials run GCS (gcs-skin/webgpu passes its TSL kit). Default: the GLSL kit (WebGLRenderer). */
  gpuKit?: GpuMaterialKit;
}

/**
 * `count` instances of `source`'s skin, each with its own pose. `source` is only read (its
 * geometry, skin and material): it is not changed and need not be in the scene. Poses are skin
 * matrices per instance (`skins`, J × 16 floats each at `offsetOf(i)`, what deformers take).
 * Placement: `mesh.setMatrixAt(i, matrix)` (three.js InstancedMesh). Frustum culling is off
 * (one draw call draws every instance). Morph targets are not carried (three.js's per-instance
 * morphs would need a morph texture per instance). `dispose()` frees the wasm memory, geometry,
 * texture and patched materials (not the source's material).
 *
 * @example
 * ```ts
 * const crowd = new GcsCrowd(gcs, skinnedMesh, 100);           // one InstancedMesh, one draw call
 * scene.add(crowd.mesh);
 * for (let i = 0; i < 100; i++) crowd.mesh.setMatrixAt(i, new THREE.Matrix4().makeTranslation(i % 10, 0, Math.floor(i / 10)));
 * const walk = bakeClip(skinnedMesh, clip);
 * renderer.setAnimationLoop((t) => {
 *   for (let i = 0; i < 100; i++) crowd.setBakedPose(i, walk, t / 1000 + i * 0.1);
 *   crowd.update();
 *   renderer.render(scene, camera);
 * });
 * ```
 */
export class GcsCrowd {
  /** The one InstancedMesh that draws every instance: add it to the scene, place instances with `setMatrixAt`. */
  readonly mesh: THREE.InstancedMesh;
  /** The rig read from the source's skin (owned by the crowd). */
  readonly rig: Rig;
  /** The GCS model every instance shares (owned by the crowd). */
  readonly deformer: GcsDeformer;
  /** The per-frame texture and the uniforms the shader reads. */
  readonly sections: GpuSections;
  /** Number of instances. */
  readonly count: number;
  /** Joints per instance (J). */
  readonly jointCount: number;
  private isDisposed = false;
  private readonly kit: GpuMaterialKit;
  private readonly materials: GpuMaterials;
  /** Set when a renderer that cannot run the kit's materials drew the crowd; update() throws it. */
  private rendererError: GcsError | null = null;

  /**
   * @param gcs The core (`await initGcsSkin()`).
   * @param source The skinned mesh to copy; only read.
   * @param count Number of instances, 1 or more.
   * @param options The GCS model, material, texture width and GPU path.
   * @throws GcsError `INVALID_ARGUMENT` when the material cannot run GCS on the GPU (a ShaderMaterial, a
   * node material with its own position node), `NO_SKIN` when `source` is not skinned, `OUT_OF_RANGE`
   * for a bad count (default 1), and the build's codes (`GcsError`).
   */
  constructor(readonly gcs: GcsSkin, source: THREE.SkinnedMesh, count = 1, options: GcsCrowdOptions = {}) {
    checkGcsSkin(gcs, 'GcsCrowd');
    const input = rigInputFromSkinnedMesh(source);
    const material = options.material ?? source.material;
    const kit = this.kit = options.gpuKit ?? glslKit;
    for (const m of Array.isArray(material) ? material : [material]) {
      const reason = kit.support(m);
      if (reason) throw new GcsError('INVALID_ARGUMENT', `GcsCrowd draws on the GPU only: ${reason}`);
    }
    this.rig = gcs.createRig(input);
    let deformer: GcsDeformer | null = null, sections: GpuSections | null = null;
    try {
      deformer = this.rig.buildGcs(options.gcs ?? {});
      const path = options.gpuPath ?? 'auto';
      sections = new GpuSections(deformer, count, options.maxTextureWidth ?? 2048, path === 'auto' ? undefined : path);
    } catch (e) {
      deformer?.dispose();
      this.rig.dispose();
      throw e;
    }
    this.deformer = deformer;
    this.sections = sections;
    this.count = count;
    this.jointCount = this.rig.jointCount;
    // The bind pose, the section data, the carried attributes (no morphs: see above).
    const geometry = bindGeometry(deformer, this.jointCount, source.geometry, { tangents: true, morphs: false });
    for (const g of source.geometry.groups) geometry.addGroup(g.start, g.count, g.materialIndex);
    this.mesh = new THREE.InstancedMesh(geometry, undefined, count);
    this.materials = kit.build(material, sections, this.mesh.instanceMatrix);
    this.mesh.material = this.materials.material;
    if (this.materials.depth) this.mesh.customDepthMaterial = this.materials.depth;
    if (this.materials.distance) this.mesh.customDistanceMaterial = this.materials.distance;
    this.mesh.onBeforeRender = (renderer, _scene, _camera, drawn, drawnMaterial) => {
      if (!this.rendererError) this.checkRenderer(renderer, drawn, drawnMaterial);
    };
    // Shadow maps are drawn before the scene: the node pass runs at the first of either.
    this.mesh.onBeforeShadow = (renderer, _object, _camera, _shadowCamera, drawn, drawnMaterial) => {
      if (!this.rendererError) this.checkRenderer(renderer, drawn, drawnMaterial);
    };
    // A crowd has no CPU backend: a shader that failed to compile stops it with a note (update() throws it).
    const compiled = (renderer: unknown, drawn: THREE.BufferGeometry, drawnMaterial: THREE.Material) => {
      const why = this.rendererError ? null : this.materials.compileError?.(renderer, drawnMaterial);
      if (why) this.stop(drawn, why);
    };
    this.mesh.onAfterRender = (renderer, _scene, _camera, drawn, drawnMaterial) => compiled(renderer, drawn, drawnMaterial);
    this.mesh.onAfterShadow = (renderer, _object, _camera, _shadowCamera, drawn, drawnMaterial) => compiled(renderer, drawn, drawnMaterial);
    this.mesh.castShadow = source.castShadow;
    this.mesh.receiveShadow = source.receiveShadow;
    this.mesh.frustumCulled = false;
    this.mesh.name = `${source.name || 'skin'} (GCS crowd)`;
  }

  private live(): void {
    if (this.isDisposed) throw new GcsError('DISPOSED', 'this GcsCrowd has been disposed');
  }

  /**
   * At each draw: a renderer that cannot run the kit's materials would draw every instance in the
   * bind pose (or nothing). A crowd has no CPU backend, so the crowd stops drawing, one console
   * warning says why, and the next update() throws GcsError 'INVALID_ARGUMENT' naming the fix.
   */
  private checkRenderer(renderer: unknown, geometry: THREE.BufferGeometry, material: THREE.Material): void {
    let why = this.kit.mismatch(renderer, material);
    if (!why) {
      // The joint-level path's node pass, once per frame for every instance; it needs float render targets.
      const noPass = this.materials.beforeDraw?.(renderer) ?? null;
      if (noPass) why = `${noPass}: build the crowd with gpuPath: 'sections'`;
    }
    if (why) this.stop(geometry, why);
  }

  /** Stops drawing with one warning; the next update() throws why. */
  private stop(geometry: THREE.BufferGeometry, why: string): void {
    geometry.setDrawRange(0, 0);
    this.rendererError = new GcsError('INVALID_ARGUMENT', `GcsCrowd (${this.kit.entry}): ${why}`);
    console.warn(`gcs-skin: ${this.rendererError.message}`);
  }

  /** Every instance's skin matrices (count × J × 16 floats), a view on wasm memory: write poses here. */
  get skins(): Float32Array {
    this.live();
    return this.sections.skins;
  }

  /** Where instance i's J × 16 skin matrices start in `skins`. */
  offsetOf(i: number): number {
    if (!Number.isInteger(i) || i < 0 || i >= this.count) throw new GcsError('OUT_OF_RANGE', `instance ${asGiven(i)} is out of range: the crowd has ${this.count}`);
    return i * this.jointCount * 16;
  }

  /** Poses instance i at `time` seconds into a baked clip (looped; the nearest sampled frame). A copy of J × 16 floats. */
  setBakedPose(i: number, clip: BakedClip, time: number): void {
    if (!(clip?.data instanceof Float32Array)) throw new GcsError('INVALID_ARGUMENT', 'setBakedPose takes a clip that bakeClip made');
    if (clip.jointCount !== this.jointCount) throw new GcsError('LENGTH_MISMATCH', `the clip was baked for ${clip.jointCount} joints; the crowd has ${this.jointCount}`);
    const o = this.offsetOf(i);
    const n = this.jointCount * 16;
    let f = Math.floor(time * clip.fps) % clip.frames;
    if (f < 0) f += clip.frames;
    if (!(f >= 0)) f = 0; // NaN or infinite time: the first frame
    const src = clip.data, dst = this.skins, s = f * n;
    for (let k = 0; k < n; k++) dst[o + k] = src[s + k];
  }

  /** Once per frame after posing: every instance's joint poses or section transforms (one wasm call); the texture uploads at the next render. */
  update(): void {
    this.live();
    if (this.rendererError) throw this.rendererError;
    this.sections.update();
  }

  /** Bytes uploaded per update(): the per-frame texture (joint poses or section transforms). */
  get bytesPerFrame(): number {
    return this.sections.bytesPerUpdate;
  }

  /** Frees the wasm memory, geometry, texture and patched materials; the source's material stays. */
  dispose(): void {
    if (this.isDisposed) return;
    this.isDisposed = true;
    this.mesh.removeFromParent();
    this.mesh.geometry.dispose();
    disposeGpuMaterials(this.materials);
    this.mesh.dispose();
    this.sections.dispose();
    this.deformer.dispose();
    this.rig.dispose();
  }

  /** Whether `dispose()` has run (`update()` then throws GcsError `DISPOSED`). */
  get disposed(): boolean {
    return this.isDisposed;
  }
}
