/**
 * The TSL kit (WebGPURenderer, real WebGPU or its WebGL2 fallback): each source material becomes
 * its node equivalent (every map, colour and flag kept, as WebGPURenderer itself converts
 * built-in materials) with GCS as its `positionNode` (tsl.ts); the shadow passes use the same
 * node (`castShadowPositionNode`), so shadows follow the skin.
 */
import * as THREE from 'three/webgpu';
import { checkMaterial } from '../arguments.js';
import { GcsError } from '../errors.js';
import type { GpuMaterialKit, GpuMaterials } from './kit.js';
import type { GpuSections } from './sections.js';
import { TslNodePass } from './node-pass-tsl.js';
import { gcsPositionNode, previousPositionNode } from './tsl.js';

/** Built-in material type → its node material (the ones WebGPURenderer converts). */
const NODE_MATERIALS: Record<string, new () => THREE.NodeMaterial> = {
  MeshBasicMaterial: THREE.MeshBasicNodeMaterial,
  MeshLambertMaterial: THREE.MeshLambertNodeMaterial,
  MeshPhongMaterial: THREE.MeshPhongNodeMaterial,
  MeshStandardMaterial: THREE.MeshStandardNodeMaterial,
  MeshPhysicalMaterial: THREE.MeshPhysicalNodeMaterial,
  MeshToonMaterial: THREE.MeshToonNodeMaterial,
  MeshMatcapMaterial: THREE.MeshMatcapNodeMaterial,
  MeshNormalMaterial: THREE.MeshNormalNodeMaterial,
};

/** Properties not carried from a built-in material to its node equivalent: identity and class flags, not look. */
const NOT_CARRIED = (key: string) => key === 'uuid' || key === 'type' || key === 'version' || /^is[A-Z]/.test(key);

/**
 * What a WebGLRenderer without a nodes handler (which cannot run node materials) compiles in their
 * place for the one draw before onBeforeRender moves the skin to the CPU: a program that puts every
 * vertex beyond the far plane, so nothing is drawn rather than a crash. WebGLNodesHandler and
 * WebGPURenderer never read these fields.
 */
const NOTHING = {
  vertexShader: 'void main() { gl_Position = vec4( 0.0, 0.0, 2.0, 1.0 ); }',
  fragmentShader: 'void main() { gl_FragColor = vec4( 0.0 ); }',
};

/** Uniforms for that program: WebGLRenderer wires its lights into whichever it asks for; the program reads none. */
function placeholderUniforms(): Record<string, { value: unknown }> {
  return new Proxy({} as Record<string, { value: unknown }>, { get: (target, key: string) => (target[key] ??= { value: null }) });
}

type Nodes = { positionNode?: unknown; vertexNode?: unknown; castShadowPositionNode?: unknown };

/**
 * Why `material` cannot run GCS as a node material, or null when it can.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function nodeMaterialSupport(material: THREE.Material): string | null {
  checkMaterial(material, 'material', 'nodeMaterialSupport');
  const m = material as THREE.Material & { isShaderMaterial?: boolean; isNodeMaterial?: boolean } & Nodes;
  if (m.isShaderMaterial) return `${material.type} is a custom shader: gcs-skin/webgpu runs GCS in node materials (use a built-in or node material)`;
  if (m.isNodeMaterial) {
    for (const key of ['positionNode', 'vertexNode', 'castShadowPositionNode'] as const)
      if (m[key]) return `${material.type} has its own ${key}: GCS would replace it (leave ${key} null, or deform on the CPU backend)`;
    return null;
  }
  if (!NODE_MATERIALS[material.type]) return `${material.type} has no node material equivalent: gcs-skin/webgpu runs GCS in node materials`;
  return null;
}

/**
 * The node equivalent of a built-in material (textures shared), or a clone of a node material.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function toNodeMaterial(source: THREE.Material): THREE.NodeMaterial {
  checkMaterial(source, 'source', 'toNodeMaterial');
  if ((source as THREE.NodeMaterial).isNodeMaterial) return (source as THREE.NodeMaterial).clone();
  const Node = NODE_MATERIALS[source.type];
  if (!Node) throw new GcsError('INVALID_ARGUMENT', `toNodeMaterial: ${nodeMaterialSupport(source) ?? 'this material has no node material equivalent'}`);
  const material = new Node();
  const from = source as unknown as Record<string, unknown>, to = material as unknown as Record<string, unknown>;
  for (const key in source) if (!NOT_CARRIED(key)) to[key] = from[key];
  material.userData = { ...source.userData };
  material.needsUpdate = true;
  return material;
}

/** The TSL kit: what gcs-skin/webgpu draws with. */
export const tslKit: GpuMaterialKit = {
  entry: 'gcs-skin/webgpu',
  methods: new Set(['gcs', 'lbs', 'dqs']),
  support: nodeMaterialSupport,
  build(source: THREE.Material | THREE.Material[], sections: GpuSections, instances: THREE.InstancedBufferAttribute | null): GpuMaterials {
    // Joint-level path: the node pass turns joint poses into node transforms once per frame; the vertex stage reads those.
    // DQS: the same pass, two texels per joint (its quaternion, dual part, uniform scale and scale part, once per frame).
    const pass = (sections.method === 'gcs' && sections.path === 'joints') || sections.method === 'dqs' ? new TslNodePass(sections) : null;
    const convert = (m: THREE.Material) => {
      const material = toNodeMaterial(m);
      material.positionNode = gcsPositionNode(sections, instances !== null, pass);
      material.castShadowPositionNode = material.positionNode;
      material.name = m.name;
      material.userData.gcsSource = m;
      if (pass) material.userData.gcsNodePass = pass; // what its vertex stage reads (tests read the pass back)
      Object.assign(material, { ...NOTHING, uniforms: placeholderUniforms() });
      return material;
    };
    const material = Array.isArray(source) ? source.map(convert) : convert(source);
    if (!pass) return { material, depth: null, distance: null };
    return {
      material, depth: null, distance: null,
      beforeDraw: (renderer: unknown): string | null => pass.render(renderer),
      dispose: () => pass.dispose(),
    };
  },
  mismatch(renderer: unknown, material: THREE.Material): string | null {
    const r = renderer as { isWebGLRenderer?: boolean };
    // WebGLNodesHandler installs its own onBeforeRender on the node materials it draws.
    if (r?.isWebGLRenderer && material.onBeforeRender === THREE.Material.prototype.onBeforeRender)
      return "a WebGLRenderer without a nodes handler draws this mesh, and it cannot run node materials: draw with WebGPURenderer (three/webgpu), call renderer.setNodesHandler(new WebGLNodesHandler()) (three/addons/tsl/WebGLNodesHandler.js), or import GcsCharacter / GcsCrowd from 'gcs-skin/three' for WebGLRenderer";
    return null;
  },
  drawsVelocity(renderer: unknown): boolean {
    const r = renderer as { isWebGPURenderer?: boolean; getMRT?(): { has(name: string): boolean } | null };
    return r?.isWebGPURenderer === true && r.getMRT?.()?.has('velocity') === true;
  },
  velocityMaterial(source: THREE.Material): THREE.Material | null {
    if (nodeMaterialSupport(source)) return null;
    const material = toNodeMaterial(source);
    material.positionNode = previousPositionNode();
    material.name = source.name;
    material.userData.gcsSource = source;
    return material;
  },
};
