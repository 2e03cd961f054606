/**
 * The GLSL kit (WebGLRenderer): clones of three.js's built-in materials whose vertex shader runs
 * GCS (glsl.ts) through onBeforeCompile, and matching depth / distance materials for shadows.
 */
import * as THREE from 'three';
import { GcsError } from '../errors.js';
import { patchVertexShader } from './glsl.js';
import type { GpuMaterialKit, GpuMaterials } from './kit.js';
import type { GpuPath, TableSlots } from './layout.js';
import type { GcsUniforms, GpuSections } from './sections.js';

/** Why a material cannot draw a GCS mesh on the GPU, or null when it can. */
export function gpuMaterialSupport(material: THREE.Material): string | null {
  const m = material as THREE.Material & { isShaderMaterial?: boolean; isNodeMaterial?: boolean };
  if (m.isNodeMaterial) return `${material.type} is a node material (WebGPU / TSL): gcs-skin/three patches WebGLRenderer's GLSL materials; gcs-skin/webgpu runs GCS in node materials`;
  if (m.isShaderMaterial) return `${material.type} is a custom shader: the GPU backend patches three.js's built-in materials`;
  return null;
}

/**
 * A clone of `source` (sharing its textures) whose vertex shader applies GCS section transforms
 * read from `uniforms` (path 'sections'), or blends them from the joint poses (path 'joints', with
 * `slots` joints per section in the table: GpuSections.tableSlots). The source's own
 * onBeforeCompile, if any, runs first.
 */
export function gcsMaterial<M extends THREE.Material>(source: M, uniforms: GcsUniforms, smooth: boolean, path: GpuPath = 'sections', slots: TableSlots = 4): M {
  const reason = gpuMaterialSupport(source);
  if (reason) throw new GcsError('INVALID_ARGUMENT', reason);
  const material = source.clone() as M;
  const own = source.onBeforeCompile;
  const ownKey = source.customProgramCacheKey();
  material.onBeforeCompile = (shader, renderer) => {
    own.call(source, shader, renderer);
    for (const [name, u] of Object.entries(uniforms)) if (u) shader.uniforms[name] = u;
    shader.vertexShader = patchVertexShader(shader.vertexShader, smooth, path, slots);
  };
  material.customProgramCacheKey = () => `${ownKey}|gcs-${smooth ? 'smooth' : 'plain'}-${path}${path === 'joints' ? `-${slots}` : ''}`;
  material.name = source.name;
  material.userData.gcsSource = source;
  return material;
}

/**
 * Shadow materials for a GCS mesh: depth (directional and spot lights) and distance (point
 * lights), patched the same way; alpha-tested maps carried so cut-outs cast the right shadow.
 */
export function gcsShadowMaterials(source: THREE.Material, uniforms: GcsUniforms, smooth: boolean, path: GpuPath = 'sections', slots: TableSlots = 4): {
  /** For directional and spot lights' shadows (`customDepthMaterial`). */
  depth: THREE.MeshDepthMaterial;
  /** For point lights' shadows (`customDistanceMaterial`). */
  distance: THREE.MeshDistanceMaterial;
} {
  const depth = new THREE.MeshDepthMaterial({ depthPacking: THREE.RGBADepthPacking });
  const distance = new THREE.MeshDistanceMaterial();
  const s = source as THREE.Material & { map?: THREE.Texture | null; alphaMap?: THREE.Texture | null };
  for (const m of [depth, distance]) {
    if (source.alphaTest > 0) {
      m.alphaTest = source.alphaTest;
      m.map = s.map ?? null;
      m.alphaMap = s.alphaMap ?? null;
    }
  }
  return { depth: gcsMaterial(depth, uniforms, smooth, path, slots), distance: gcsMaterial(distance, uniforms, smooth, path, slots) };
}

/** The GLSL kit: what gcs-skin/three and gcs-skin/crowd draw with. */
export const glslKit: GpuMaterialKit = {
  entry: 'gcs-skin/three',
  support: gpuMaterialSupport,
  build(source: THREE.Material | THREE.Material[], sections: GpuSections): GpuMaterials {
    const { uniforms, smooth, path, tableSlots } = sections;
    const patch = (m: THREE.Material) => gcsMaterial(m, uniforms, smooth, path, tableSlots);
    const material = Array.isArray(source) ? source.map(patch) : patch(source);
    const shadow = gcsShadowMaterials(Array.isArray(source) ? source[0] : source, uniforms, smooth, path, tableSlots);
    return { material, depth: shadow.depth, distance: shadow.distance };
  },
  mismatch(renderer: unknown): string | null {
    const r = renderer as { isWebGPURenderer?: boolean; isWebGLRenderer?: boolean };
    if (r?.isWebGPURenderer) return "WebGPURenderer draws this mesh, and it never runs the GLSL patch of gcs-skin/three's GPU backend: import GcsCharacter / GcsCrowd from 'gcs-skin/webgpu' for GCS on the GPU there";
    return null;
  },
  // WebGLRenderer has no velocity pass; gcs-skin/webgpu's kit hands WebGPURenderer's the previous positions.
  drawsVelocity: () => false,
  velocityMaterial: () => null,
};
