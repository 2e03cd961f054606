// The one place where what three.js reads of wasm memory stays live. Growing a WebAssembly.Memory
// (any rig's build may) detaches its old ArrayBuffer: every typed array on it reads as empty, so
// a raycast, a bounds pass or a texture upload between the growth and the next update() would see
// NaN or nothing. keepLive makes such a property re-view live memory on its next read.
import type * as THREE from 'three';
import type { Deformer } from '../index.js';

/**
 * Turns `holder[key]` (a typed array on wasm memory: an attribute's `array`, a DataTexture
 * image's `data`) into a property that, when read after memory growth detached its buffer, takes
 * `read()`'s fresh view instead (null: keep the old one, e.g. its owner was disposed). Writes
 * still set it (the per-frame re-pointing of swapped arrays). The check on a live view is one
 * comparison: no allocation, nothing per vertex.
 */
export function keepLive<K extends string>(holder: { [key in K]: ArrayBufferView }, key: K, read: () => ArrayBufferView | null): void {
  let view = holder[key];
  Object.defineProperty(holder, key, {
    configurable: true,
    enumerable: true,
    get(): ArrayBufferView {
      if (view.buffer.byteLength === 0) view = read() ?? view; // detached by memory growth
      return view;
    },
    set(value: ArrayBufferView) {
      view = value;
    },
  });
}

/** The deformer's output arrays an attribute can show. */
export type DeformerOutput = 'positions' | 'normals' | 'tangents' | 'previousPositions';

/** Makes `attribute` (a view of `deformer`'s `output`) follow the deformer's live view; none after the deformer's dispose. */
export function keepAttributeLive(attribute: THREE.BufferAttribute, deformer: Deformer, output: DeformerOutput): THREE.BufferAttribute {
  keepLive(attribute as unknown as { array: ArrayBufferView }, 'array', () => (deformer.disposed ? null : deformer[output]));
  return attribute;
}
