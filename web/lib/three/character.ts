// A whole character (every SkinnedMesh under a root) deformed in wasm, in place.
import type * as THREE from 'three';
import { GcsError } from '../errors.js';
import type { DeformerKind, GcsSkin } from '../index.js';
import type { PendingBuild } from './build.js';
import type { Backend, GcsCharacterOptions, RebuildOptions } from './options.js';
import { checkGcsSkin } from './check-gcs.js';
import { commonAncestor, updateWorld } from './scene-graph.js';
import { SkeletonPoses } from './skeleton-poses.js';
import { SkinDeformer } from './skin-deformer.js';

/**
 * A whole character deformed in wasm, in place: every SkinnedMesh under `root` (a glTF scene or
 * any Object3D, several skins on one or several skeletons) gets a deformed THREE.Mesh under the
 * same parent with the same local transform, material (the same object: textures, vertex
 * colours, normal maps), attributes, shadow flags, name, layers and renderOrder; the SkinnedMesh
 * leaves the render, shadows and raycasts (its layers are cleared) but stays in the graph, so the
 * mixer keeps driving its bones and morph influences. Adding `root` to your scene is all it
 * takes. Morph targets: GCS, LBS and DQS (the classic model resamples the mesh and skips them).
 *
 * `dispose()` frees every skin's wasm memory and deformed geometry, removes the deformed meshes
 * and shows the SkinnedMeshes again. Throws GcsError 'NO_SKIN' if root holds no SkinnedMesh; a
 * skin that cannot be built (GcsError) undoes the ones already built.
 *
 * @example
 * ```ts
 * const gcs = await initGcsSkin();
 * const gltf = await new GLTFLoader().loadAsync('character.glb');
 * const character = new GcsCharacter(gcs, gltf.scene, { method: 'gcs', gcs: { sections: 8 } });
 * scene.add(gltf.scene);
 * // each frame: mixer.update(dt); character.update(); renderer.render(scene, camera);
 * character.rebuild('dqs');   // another method, in place
 * character.dispose();        // the SkinnedMeshes drawn again
 * ```
 */
export class GcsCharacter {
  /** The object whose SkinnedMeshes are deformed (your glTF scene). */
  readonly root: THREE.Object3D;
  /** One per SkinnedMesh, in traversal order. */
  readonly skins: readonly SkinDeformer[];
  /** The deformed meshes, in the order of `skins`. */
  readonly meshes: readonly THREE.Mesh[];
  /** What update() refreshes: root, or a common ancestor of root and bones kept outside it. */
  private readonly scope: THREE.Object3D;
  private isDisposed = false;
  /** Each skeleton posed once a frame, whatever the number of skins on it. */
  private readonly poses = new SkeletonPoses();
  private readonly skinUpdate = Object.freeze({ updateMatrixWorld: false, poses: this.poses });

  /**
   * @param gcs The core (`await initGcsSkin()`).
   * @param root A glTF scene or any Object3D holding SkinnedMeshes.
   * @param options Method, model options, backend, and a filter of which skins to take.
   * @throws GcsError `NO_SKIN` when `root` holds no SkinnedMesh; a skin that cannot be built throws its
   * code (GcsError) after undoing the ones already built.
   */
  constructor(readonly gcs: GcsSkin, root: THREE.Object3D, options: GcsCharacterOptions = {}) {
    checkGcsSkin(gcs, 'GcsCharacter');
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
   * then each skeleton posed once (the skins sharing it read the same skin matrices) and every
   * skin deforms. No allocation.
   */
  update(): void {
    if (this.isDisposed) throw new GcsError('DISPOSED', 'this GcsCharacter has been disposed');
    updateWorld(this.scope);
    this.poses.nextFrame();
    const skins = this.skins;
    for (let i = 0; i < skins.length; i++) skins[i].update(this.skinUpdate);
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

  /** Whether `dispose()` has run. */
  get disposed(): boolean {
    return this.isDisposed;
  }
}

