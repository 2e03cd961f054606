// Reads accessor values straight from a glTF's buffers, for the checks that need values and not
// only sizes (validate.ts: key times, sparse indices; the demo: all-zero skin weights). No
// decoding: an accessor in a meshopt-compressed or Draco buffer view, or in a buffer whose bytes
// are not at hand, is not readable here (null), and those checks then leave it to the loaders.
// Browser-safe: no node module, so the demo validates with the same code as the CLI.
import type * as THREE from 'three';
import type { BufferData, GltfJson } from './json.js';

/** Component i of element e. */
export type ComponentReader = (element: number, component: number) => number;

const COMPONENT_SIZE: Record<number, number> = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
const COMPONENTS: Record<string, number> = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };

/** A reader of `count` elements of `components` numbers each, `stride` bytes apart, or null when the bytes are not at hand. */
function reader(
  json: GltfJson, buffers: readonly (BufferData | undefined)[], bufferView: number, byteOffset: number,
  componentType: number, components: number, stride: number | undefined, normalized: boolean,
): ComponentReader | null {
  const view = json.bufferViews?.[bufferView];
  if (!view || view.extensions?.EXT_meshopt_compression) return null;
  const bytes = buffers[view.buffer]?.bytes;
  if (!bytes) return null;
  const size = COMPONENT_SIZE[componentType];
  const step = stride ?? view.byteStride ?? size * components;
  const data = new DataView(bytes.buffer, bytes.byteOffset + (view.byteOffset ?? 0) + byteOffset, view.byteLength - byteOffset);
  // The validator has checked that every element lies inside the view.
  switch (componentType) {
    case 5126: return (e, c) => data.getFloat32(e * step + 4 * c, true);
    case 5125: return (e, c) => data.getUint32(e * step + 4 * c, true);
    case 5123: return normalized ? (e, c) => data.getUint16(e * step + 2 * c, true) / 65535 : (e, c) => data.getUint16(e * step + 2 * c, true);
    case 5122: return normalized ? (e, c) => Math.max(data.getInt16(e * step + 2 * c, true) / 32767, -1) : (e, c) => data.getInt16(e * step + 2 * c, true);
    case 5121: return normalized ? (e, c) => data.getUint8(e * step + c) / 255 : (e, c) => data.getUint8(e * step + c);
    case 5120: return normalized ? (e, c) => Math.max(data.getInt8(e * step + c) / 127, -1) : (e, c) => data.getInt8(e * step + c);
    default: return null;
  }
}

/** The dense values of accessor `a` (its buffer view; sparse substitutions not applied), or null. */
export function accessorReader(json: GltfJson, buffers: readonly (BufferData | undefined)[], a: GltfJson): ComponentReader | null {
  if (a.bufferView === undefined) return null;
  return reader(json, buffers, a.bufferView, a.byteOffset ?? 0, a.componentType, COMPONENTS[a.type], undefined, a.normalized === true);
}

/** The sparse part of accessor `a`: its indices and a reader of its values, or null. */
export function sparseReader(json: GltfJson, buffers: readonly (BufferData | undefined)[], a: GltfJson):
  { count: number; index: (k: number) => number; value: ComponentReader } | null {
  const s = a.sparse;
  if (!s) return null;
  const index = reader(json, buffers, s.indices.bufferView, s.indices.byteOffset ?? 0, s.indices.componentType, 1, COMPONENT_SIZE[s.indices.componentType], false);
  const components = COMPONENTS[a.type];
  const value = reader(json, buffers, s.values.bufferView, s.values.byteOffset ?? 0, a.componentType, components,
    COMPONENT_SIZE[a.componentType] * components, a.normalized === true);
  if (!index || !value) return null;
  return { count: s.count, index: (k) => index(k, 0), value };
}

/**
 * Vertices whose skin weights are all 0, per skinned primitive ("mesh/primitive" → vertex
 * indices): three's GLTFLoader binds them to the first joint, so a caller gives them back their
 * zeros and the core reports them. Primitives whose weights are not readable here are skipped.
 */
export function zeroWeightVertices(json: GltfJson, buffers: readonly (BufferData | undefined)[]): Map<string, number[]> {
  const out = new Map<string, number[]>();
  const skinnedMeshes = new Set<number>();
  for (const node of json.nodes ?? []) if (node.skin !== undefined && node.mesh !== undefined) skinnedMeshes.add(node.mesh);
  for (const mi of skinnedMeshes) {
    (json.meshes[mi].primitives as GltfJson[]).forEach((p, pi) => {
      const sets: ComponentReader[] = [];
      for (let k = 0; p.attributes[`WEIGHTS_${k}`] !== undefined; k++) {
        const a = json.accessors[p.attributes[`WEIGHTS_${k}`]];
        const read = a.sparse ? null : accessorReader(json, buffers, a);
        if (!read) return;
        sets.push(read);
      }
      if (!sets.length) return;
      const count = json.accessors[p.attributes.WEIGHTS_0].count;
      const zero: number[] = [];
      for (let v = 0; v < count; v++) {
        let any = false;
        for (const read of sets) for (let c = 0; c < 4 && !any; c++) any = read(v, c) !== 0;
        if (!any) zero.push(v);
      }
      if (zero.length) out.set(`${mi}/${pi}`, zero);
    });
  }
  return out;
}

/**
 * Gives the vertices of `zeroWeights` (zeroWeightVertices, or computed after decoding) back their
 * all-zero weights after three's GLTFLoader bound them to the first joint, so that createRig
 * reports them (BAD_WEIGHTS) instead of deforming them with a joint they do not have.
 * `associations`: the GLTFLoader parser's map from objects to their glTF mesh and primitive.
 */
export function restoreZeroWeights(
  meshes: readonly THREE.SkinnedMesh[], associations: Map<object, { meshes?: number; primitives?: number }>, zeroWeights: Map<string, number[]>,
): void {
  if (!zeroWeights.size) return;
  for (const mesh of meshes) {
    const at = associations.get(mesh);
    const zero = at && zeroWeights.get(`${at.meshes}/${at.primitives ?? 0}`);
    const weights = mesh.geometry.getAttribute('skinWeight');
    if (zero && weights) for (const v of zero) weights.setXYZW(v, 0, 0, 0, 0);
  }
}
