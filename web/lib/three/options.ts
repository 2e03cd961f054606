// The options of gcs-skin/three's SkinDeformer and GcsCharacter (and gcs-skin/webgpu's).
import type * as THREE from 'three';
import type { ClassicOptions, DeformerKind, GcsOptions } from '../index.js';
import type { GpuMaterialKit } from '../gpu/kit.js';
import type { GpuPath } from '../gpu/layout.js';

/** Where the per-vertex work runs: 'cpu' (wasm fills the vertex buffers) or 'gpu' (the vertex shader applies GCS section transforms). */
export type Backend = 'cpu' | 'gpu';

/** Options of `SkinDeformer`: the method and its model, material, placement, tangents and backend. */
export interface SkinDeformerOptions {
  /** Which deformer drives the mesh. Default 'gcs'. */
  method?: DeformerKind;
  /** Options of the GCS model (method `'gcs'`): sections, criterion, smooth, centres. */
  gcs?: GcsOptions;
  /** Options of the classic model (method `'classic'`): contours, rays, bulge. */
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
   * with the skin (the deformer's own pass: one deform call writes positions, normals and
   * tangents; the GPU backend turns them in the shader); 'drop' leaves them out, and three.js derives the tangent frame
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
   * see gpuPath). GCS, LBS and DQS: the classic model, materials that cannot
   * be patched (ShaderMaterial, node materials) and a patched shader that fails to compile fall back
   * to 'cpu' — `backend` tells which runs, `backendNote` why, and one console warning says so. The
   * same happens at the first draw by a WebGPURenderer, which never runs the patch: gcs-skin/webgpu
   * is the GPU backend for it (TSL).
   */
  backend?: Backend;
  /**
   * GPU backend: what wasm hands the GPU per frame. 'auto' (default): 'joints' for the weights
   * criterion (the joint poses, 64 bytes per joint; a node pass blends each section from them and
   * a static table once per frame, the vertex shader reads the result), 'sections' for 'y' and 'axial' (the section transforms, 48 bytes per section).
   * 'sections' forces the section-level path; 'joints' with 'y' or 'axial' is GcsError
   * 'INVALID_ARGUMENT'.
   */
  gpuPath?: GpuPath | 'auto';
  /** @internal How materials run GCS on the GPU (gcs-skin/webgpu passes its TSL kit). Default: the GLSL kit (WebGLRenderer). */
  gpuKit?: GpuMaterialKit;
  /** @internal The backend notes already warned about (a GcsCharacter shares one set: one warning per cause). */
  warned?: Set<string>;
}

/** What rebuild() may change. */
export interface RebuildOptions {
  /** Options of the GCS model (method `'gcs'`): sections, criterion, smooth, centres. */
  gcs?: GcsOptions;
  /** Options of the classic model (method `'classic'`): contours, rays, bulge. */
  classic?: ClassicOptions;
  /** Where the per-vertex work runs from now on (default: as before). */
  backend?: Backend;
  /** The GPU backend's path from now on (see SkinDeformerOptions.gpuPath). */
  gpuPath?: GpuPath | 'auto';
}

/** Options of `GcsCharacter`: those of `SkinDeformer` for every skin, and a filter of which skins to take. */
export interface GcsCharacterOptions {
  /** Which deformer drives every skin. Default 'gcs'. */
  method?: DeformerKind;
  /** Options of the GCS model (method `'gcs'`): sections, criterion, smooth, centres. */
  gcs?: GcsOptions;
  /** Options of the classic model (method `'classic'`): contours, rays, bulge. */
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
