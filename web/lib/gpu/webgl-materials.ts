/**
 * The GLSL kit (WebGLRenderer): clones of three.js's built-in materials whose vertex shader runs
 * GCS (glsl.ts) through onBeforeCompile, and matching depth / distance materials for shadows.
 */
import * as THREE from 'three';
import { GcsError } from '../errors.js';
import { checkMaterial, checkObject } from '../arguments.js';
import { checkVariant, patchVertexShader, placedInNodes } from './glsl.js';
import type { GpuMaterialKit, GpuMaterials } from './kit.js';
import type { GpuMethod, GpuPath, TableSlots } from './layout.js';
import { NodePass } from './node-pass.js';
import type { GcsUniforms, GpuSections } from './sections.js';

/**
 * Why a material cannot draw a GCS mesh on the GPU, or null when it can.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function gpuMaterialSupport(material: THREE.Material): string | null {
  checkMaterial(material, 'material', 'gpuMaterialSupport');
  const m = material as THREE.Material & { isShaderMaterial?: boolean; isNodeMaterial?: boolean };
  if (m.isNodeMaterial) return `${material.type} is a node material (WebGPU / TSL): gcs-skin/three patches WebGLRenderer's GLSL materials; gcs-skin/webgpu runs GCS in node materials`;
  if (m.isShaderMaterial) return `${material.type} is a custom shader: the GPU backend patches three.js's built-in materials`;
  return null;
}

/**
 * A clone of `source` (sharing its textures) whose vertex shader applies GCS section transforms
 * read from `uniforms`: path 'sections', GpuSections.uniforms; path 'joints', the node pass's
 * (NodePass.uniforms: each node's transform, computed once per frame from the joint poses). The
 * source's own onBeforeCompile, if any, runs first.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function gcsMaterial<M extends THREE.Material>(source: M, uniforms: GcsUniforms, smooth: boolean, path: GpuPath = 'sections', method: GpuMethod = 'gcs', slots: TableSlots = 4): M {
  checkMaterial(source, 'source', 'gcsMaterial');
  checkObject(uniforms, 'uniforms', 'gcsMaterial');
  checkVariant(path, method, slots, 'gcsMaterial');
  const reason = gpuMaterialSupport(source);
  if (reason) throw new GcsError('INVALID_ARGUMENT', reason);
  const material = source.clone() as M;
  const own = source.onBeforeCompile;
  const ownKey = source.customProgramCacheKey();
  material.onBeforeCompile = (shader, renderer) => {
    own.call(source, shader, renderer);
    for (const [name, u] of Object.entries(uniforms)) if (u) shader.uniforms[name] = u;
    shader.vertexShader = patchVertexShader(shader.vertexShader, smooth, path, method, slots);
  };
  material.customProgramCacheKey = () => `${ownKey}|gcs-${method === 'gcs' ? `${smooth ? 'smooth' : 'plain'}-${path}` : `${method}-${slots}`}`;
  material.name = source.name;
  material.userData.gcsSource = source;
  material.userData.gcsUniforms = uniforms; // what its vertex stage reads (tests read the shader's output with them)
  return material;
}

/**
 * Shadow materials for a GCS mesh: depth (directional and spot lights) and distance (point
 * lights), patched the same way; alpha-tested maps carried so cut-outs cast the right shadow.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function gcsShadowMaterials(source: THREE.Material, uniforms: GcsUniforms, smooth: boolean, path: GpuPath = 'sections', method: GpuMethod = 'gcs', slots: TableSlots = 4): {
  /** For directional and spot lights' shadows (`customDepthMaterial`). */
  depth: THREE.MeshDepthMaterial;
  /** For point lights' shadows (`customDistanceMaterial`). */
  distance: THREE.MeshDistanceMaterial;
} {
  checkMaterial(source, 'source', 'gcsShadowMaterials');
  checkObject(uniforms, 'uniforms', 'gcsShadowMaterials');
  checkVariant(path, method, slots, 'gcsShadowMaterials');
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
  return { depth: gcsMaterial(depth, uniforms, smooth, path, method, slots), distance: gcsMaterial(distance, uniforms, smooth, path, method, slots) };
}

/**
 * Why the program WebGLRenderer built for `material` did not compile or link (three.js's own
 * check, `renderer.debug.checkShaderErrors`, on by default), or null: a patched shader that fails
 * draws nothing, and the skin must not stay so in silence.
 */
function compileError(renderer: unknown, material: THREE.Material): string | null {
  const r = renderer as { isWebGLRenderer?: boolean; properties?: { get(m: object): { currentProgram?: { diagnostics?: { runnable: boolean; vertexShader: { log: string }; programLog: string } } } } };
  if (!r?.isWebGLRenderer || !material.userData.gcsUniforms) return null;
  const diagnostics = r.properties?.get(material).currentProgram?.diagnostics;
  if (!diagnostics || diagnostics.runnable) return null;
  const log = (diagnostics.vertexShader.log || diagnostics.programLog).split('\n')[0].trim();
  return `${material.type}'s GCS shader did not compile on this WebGLRenderer${log ? ` (${log})` : ''}`;
}

/** A patched crowd material whose node pass places the instances: its vertex stage leaves three.js's instancing out (placedInNodes). */
function placeInNodes<M extends THREE.Material>(material: M): M {
  const patch = material.onBeforeCompile, key = material.customProgramCacheKey();
  material.onBeforeCompile = (shader, renderer) => {
    patch.call(material, shader, renderer);
    shader.vertexShader = placedInNodes(shader.vertexShader);
  };
  material.customProgramCacheKey = () => `${key}|placed`;
  return material;
}

/** The GLSL kit: what gcs-skin/three and gcs-skin/crowd draw with. */
export const glslKit: GpuMaterialKit = {
  entry: 'gcs-skin/three',
  methods: new Set(['gcs', 'lbs', 'dqs']),
  support: gpuMaterialSupport,
  build(source: THREE.Material | THREE.Material[], sections: GpuSections, instances: THREE.InstancedBufferAttribute | null): GpuMaterials {
    const { smooth, path, method, tableSlots } = sections;
    const nodes = method === 'gcs' && path === 'joints';
    // GCS, joint-level: the node pass turns joint poses into node transforms once per frame; the vertex stage reads those.
    // A crowd's: with each instance's placement folded in, once per node, not once per vertex.
    // DQS: the same pass, one fragment per joint (its quaternion and scale part, once per frame).
    const placed = nodes && instances !== null;
    const pass = nodes || method === 'dqs' ? new NodePass(sections, false, undefined, placed ? instances : null) : null;
    const uniforms = pass ? pass.uniforms : sections.uniforms;
    const patch = <M extends THREE.Material>(m: M): M => (placed ? placeInNodes(gcsMaterial(m, uniforms, smooth, path, method, tableSlots)) : gcsMaterial(m, uniforms, smooth, path, method, tableSlots));
    const material = Array.isArray(source) ? source.map(patch) : patch(source);
    if (pass) for (const m of Array.isArray(material) ? material : [material]) m.userData.gcsNodePass = pass; // what its vertex stage reads (tests read the pass back)
    const shadowMaterials = gcsShadowMaterials(Array.isArray(source) ? source[0] : source, uniforms, smooth, path, method, tableSlots);
    const shadow = placed ? { depth: placeInNodes(shadowMaterials.depth), distance: placeInNodes(shadowMaterials.distance) } : shadowMaterials;
    if (!pass) return { material, depth: shadow.depth, distance: shadow.distance, compileError };
    return {
      material, depth: shadow.depth, distance: shadow.distance, compileError,
      beforeDraw(renderer: unknown): string | null {
        const why = NodePass.unsupported(renderer);
        if (why || !(renderer as { isWebGLRenderer?: boolean })?.isWebGLRenderer) return why;
        return pass.render(renderer as THREE.WebGLRenderer);
      },
      dispose: () => pass.dispose(),
    };
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
