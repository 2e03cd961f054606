/**
 * The GPU backend's bind-pose mesh, shared by gcs-skin/three, gcs-skin/crowd and gcs-skin/webgpu:
 * the identity skin, the bind-pose positions and normals in the deformer's output order with the
 * per-vertex section data, and the source's other attributes carried in that order.
 */
import * as THREE from 'three';
import type { Deformer, GcsDeformer } from '../index.js';
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
export function bindGeometry(deformer: GcsDeformer, jointCount: number, source: THREE.BufferGeometry, options: BindGeometryOptions): THREE.BufferGeometry {
  const geometry = new THREE.BufferGeometry();
  geometry.setIndex(new THREE.BufferAttribute(deformer.indices, 1));
  deformer.deform(identitySkin(jointCount));
  geometry.setAttribute('position', new THREE.BufferAttribute(deformer.positions.slice(), 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(deformer.normals.slice(), 3));
  for (const { name, attribute } of sectionAttributes(deformer)) geometry.setAttribute(name, attribute);
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

