/**
 * What differs between the renderers for the GPU backend: how a source material becomes one that
 * runs GCS in its vertex stage. gcs-skin/three and gcs-skin/crowd use the GLSL kit
 * (webgl-materials.ts, WebGLRenderer); gcs-skin/webgpu the TSL kit (node-materials.ts,
 * WebGPURenderer). Everything else (wasm, textures, bind geometry) is shared.
 */
import type * as THREE from 'three';
import type { GpuSections } from './sections.js';

/** The materials of one GPU build. */
export interface GpuMaterials {
  material: THREE.Material | THREE.Material[];
  /** customDepthMaterial / customDistanceMaterial for the shadow passes, or null where the material casts its own (node materials). */
  depth: THREE.Material | null;
  distance: THREE.Material | null;
  /**
   * Before each draw of the skin (shadow or colour pass), with the renderer drawing it: runs what
   * must run once per frame before the vertex stage (the node pass). Returns why this renderer
   * cannot, or null.
   */
  beforeDraw?(renderer: unknown): string | null;
  /**
   * After a draw of the skin with `material`: why its patched shader failed to compile or link
   * (the GPU backend then falls back, rather than draw nothing), or null.
   */
  compileError?(renderer: unknown, material: THREE.Material): string | null;
  /** Frees what beforeDraw needs (the node pass's target). */
  dispose?(): void;
}

export interface GpuMaterialKit {
  /** The package entry that draws with this kit (named in notes and errors). */
  readonly entry: string;
  /** The methods its GPU backend runs ('gcs'; the GLSL kit also 'lbs' and 'dqs'). */
  readonly methods: ReadonlySet<string>;
  /** Why `material` cannot draw GCS through this kit, or null when it can. */
  support(material: THREE.Material): string | null;
  /**
   * Clones of `source` (textures shared) whose vertex stage applies GCS from `sections`;
   * `instances`: the crowd's instance matrices (each instance placed after GCS), or null.
   */
  build(source: THREE.Material | THREE.Material[], sections: GpuSections, instances: THREE.InstancedBufferAttribute | null): GpuMaterials;
  /**
   * Why the renderer now drawing `material` (from onBeforeRender) cannot run these materials, or
   * null when it can. Checked at each draw: the renderer is known only then.
   */
  mismatch(renderer: unknown, material: THREE.Material): string | null;
  /** Whether `renderer` is drawing a pass that writes velocity (motion vectors) now. */
  drawsVelocity(renderer: unknown): boolean;
  /**
   * CPU backend, velocity: a clone of `source` that hands the renderer each vertex's previous
   * position from the geometry's PREVIOUS_POSITION_ATTRIBUTE, or null where this kit or the
   * material cannot (the GLSL kit; custom shaders; node materials with their own position node).
   */
  velocityMaterial(source: THREE.Material): THREE.Material | null;
}

/** Frees the materials of a GPU build. */
export function disposeGpuMaterials(m: GpuMaterials): void {
  for (const x of Array.isArray(m.material) ? m.material : [m.material]) x.dispose();
  m.depth?.dispose();
  m.distance?.dispose();
  m.dispose?.();
}
