/**
 * The GPU backend's bind-pose mesh, shared by gcs-skin/three, gcs-skin/crowd and gcs-skin/webgpu:
 * the identity skin, the bind-pose positions and normals in the deformer's output order with the
 * per-vertex section data, and the source's other attributes carried in that order.
 */
import * as THREE from 'three';
import type { Deformer, GcsDeformer, RigInput } from '../index.js';
import { INFLUENCE_ATTRIBUTES, WEIGHT_ATTRIBUTES } from './layout.js';
import { sectionAttributes } from './sections.js';

/** Identity skin matrices (the bind pose) for `jointCount` joints, J × 16 floats. */
export function identitySkin(jointCount: number): Float32Array {
  const out = new Float32Array(jointCount * 16);
  for (let j = 0; j < jointCount; j++) for (let c = 0; c < 4; c++) out[16 * j + 5 * c] = 1;
  return out;
}

export interface BindGeometryOptions {
  /** Carry the source's tangents (normal maps turn them in the shader). */
  tangents: boolean;
  /** Carry the source's morph targets (the shader morphs before the section transform, three's order). */
  morphs: boolean;
}

/**
 * The GPU backend's static geometry: `deformer`'s triangles in the bind pose (a bind-pose deform
 * is bit-exact), its per-vertex section data, and `source`'s other attributes (uv, colour…,
 * tangents and morph targets as asked) remapped to the output order. Groups and draw range are
 * the caller's (they depend on the triangle order).
 */
export function bindGeometry(deformer: Deformer, jointCount: number, source: THREE.BufferGeometry, options: BindGeometryOptions,
  perVertex: readonly VertexAttribute[] = sectionAttributes(deformer as GcsDeformer)): THREE.BufferGeometry {
  const geometry = new THREE.BufferGeometry();
  geometry.setIndex(new THREE.BufferAttribute(deformer.indices, 1));
  deformer.deform(identitySkin(jointCount));
  geometry.setAttribute('position', new THREE.BufferAttribute(deformer.positions.slice(), 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(deformer.normals.slice(), 3));
  for (const { name, attribute } of perVertex) geometry.setAttribute(name, attribute);
  if (!deformer.keepsVertices) return geometry;
  for (const [key, attr] of Object.entries(source.attributes))
    if (!SKINNING_ATTRIBUTES.has(key) || (key === 'tangent' && options.tangents)) geometry.setAttribute(key, remapAttribute(attr, deformer));
  if (options.morphs) {
    for (const key of ['position', 'normal'] as const) {
      const list = source.morphAttributes[key];
      if (list?.length) geometry.morphAttributes[key] = list.map((a) => remapAttribute(a, deformer));
    }
    geometry.morphTargetsRelative = source.morphTargetsRelative;
  }
  return geometry;
}

/** A static per-vertex attribute of the GPU backend's geometry, by name. */
export interface VertexAttribute { name: string; attribute: THREE.BufferAttribute }

/**
 * LBS and DQS on the GPU: each output vertex's joints and weights as the core holds them (the
 * rig's weights divided by their largest, then by their sum, in float32, as gcs_rig_create does),
 * the joints of weight 0 as −1 after the others; 4 per vertex, 8 where the rig has a second set.
 */
export function influenceAttributes(input: RigInput, sourceVertex: Uint32Array): { attributes: VertexAttribute[]; slots: 4 | 8 } {
  const k = input.influences ?? 4, slots = k > 4 ? 8 : 4, n = sourceVertex.length;
  const ids = [new Float32Array(4 * n), new Float32Array(4 * n)], weights = [new Float32Array(4 * n), new Float32Array(4 * n)];
  const w = new Float32Array(8), j = new Float32Array(8);
  const f = Math.fround;
  for (let o = 0; o < n; o++) {
    const v = sourceVertex[o];
    let big = 0;
    w.fill(0);
    for (let i = 0; i < k; i++) { w[i] = input.weights[k * v + i]; j[i] = input.joints[k * v + i]; big = Math.max(big, w[i]); }
    let sum = 0;
    for (let i = 0; i < 8; i++) { w[i] = f(w[i] / big); sum = f(sum + w[i]); }
    let slot = 0;
    for (let pass = 0; pass < 2; pass++) // the weighted joints first, in their order; then the empty slots
      for (let i = 0; i < slots; i++) {
        if ((w[i] > 0) !== (pass === 0)) continue;
        const set = slot >> 2, at = 4 * o + (slot & 3);
        ids[set][at] = w[i] > 0 ? j[i] : -1;
        weights[set][at] = w[i] > 0 ? f(w[i] / sum) : 0;
        slot++;
      }
  }
  const attributes: VertexAttribute[] = [];
  for (let set = 0; set < slots / 4; set++) {
    attributes.push({ name: INFLUENCE_ATTRIBUTES[set], attribute: new THREE.BufferAttribute(ids[set], 4) });
    attributes.push({ name: WEIGHT_ATTRIBUTES[set], attribute: new THREE.BufferAttribute(weights[set], 4) });
  }
  return { attributes, slots };
}

export type AnyAttribute = THREE.BufferAttribute | THREE.InterleavedBufferAttribute;
type TypedArray = Float32Array | Float64Array | Int8Array | Uint8Array | Uint8ClampedArray | Int16Array | Uint16Array | Int32Array | Uint32Array;

/** @internal The attributes a deformer replaces or consumes: everything else is carried to the output. */
export const SKINNING_ATTRIBUTES: ReadonlySet<string> = new Set(['position', 'normal', 'tangent', 'skinIndex', 'skinWeight']);

/** Raw (un-normalised) element i·itemSize+k of an attribute, interleaved or not. */
function rawArray(attr: AnyAttribute): { array: TypedArray; stride: number; offset: number } {
  const inter = attr as THREE.InterleavedBufferAttribute;
  return inter.isInterleavedBufferAttribute
    ? { array: inter.data.array as TypedArray, stride: inter.data.stride, offset: inter.offset }
    : { array: (attr as THREE.BufferAttribute).array as TypedArray, stride: attr.itemSize, offset: 0 };
}

/**
 * @internal A copy of `attr` in `deformer`'s output-vertex order (output o takes source vertex
 * sourceVertex[o]), same type and normalisation: gathered in wasm, so a rebuild runs no loop per
 * vertex in JavaScript (a slider drag rebuilds every frame).
 */
export function remapAttribute(attr: AnyAttribute, deformer: Deformer): THREE.BufferAttribute {
  const { array, stride, offset } = rawArray(attr);
  const size = attr.itemSize, bytes = array.BYTES_PER_ELEMENT;
  const Ctor = array.constructor as new (buffer: ArrayBufferLike) => TypedArray;
  const start = array.byteOffset + offset * bytes;
  const source = new Uint8Array(array.buffer, start, Math.max(0, (attr.count - 1) * stride + size) * bytes);
  const out = new Ctor(deformer.gather(source, attr.count, stride * bytes, size * bytes).buffer);
  const result = (attr as { isFloat16BufferAttribute?: boolean }).isFloat16BufferAttribute
    ? new THREE.Float16BufferAttribute(out as Uint16Array, size, attr.normalized)
    : new THREE.BufferAttribute(out, size, attr.normalized);
  result.name = attr.name;
  const gpuType = (attr as THREE.BufferAttribute).gpuType;
  if (gpuType !== undefined) result.gpuType = gpuType;
  return result;
}

