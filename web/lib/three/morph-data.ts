// Morph targets of a geometry as relative deltas in its vertex order, what
// deformer.setMorphTargets takes, with each target's largest delta (for the bounds).
import type * as THREE from 'three';
import { checkMethods, checkObject } from '../arguments.js';
import { GcsError } from '../errors.js';

type AnyAttribute = THREE.BufferAttribute | THREE.InterleavedBufferAttribute;

/**
 * The one check of a geometry's morph targets, wherever it is read (the three.js adapters, the
 * command line's report and loadCharacter): every position and normal value finite, else GcsError
 * NON_FINITE naming the target and vertex (what the core says of such deltas, earlier).
 */
export function checkMorphTargets(geometry: THREE.BufferGeometry): void {
  for (const kind of ['position', 'normal'] as const) {
    (geometry.morphAttributes[kind] ?? []).forEach((attr, t) => {
      for (let i = 0; i < attr.count; i++)
        for (let k = 0; k < attr.itemSize; k++)
          if (!Number.isFinite(attr.getComponent(i, k)))
            throw new GcsError('NON_FINITE', `morph target ${t}${attr.name ? ` '${attr.name}'` : ''} has a NaN or infinite ${kind} delta at vertex ${i}`);
    });
  }
}

/**
 * Morph targets as relative deltas in the source's vertex order (glTF / three: morphTargetsRelative).
 * A relative, plain Float32 target is returned as is (not copied): treat the arrays as read-only.
 */
export interface MorphData {
  /** Per target, the position deltas (x, y, z per vertex). */
  positions: Float32Array[];
  /** Per target, the normal deltas, or null when the geometry has no normal targets. */
  normals: Float32Array[] | null;
  /** Per target, the largest delta length: bounds grow by Σ |influence| · maxDelta. */
  maxDelta: Float32Array;
}

/**
 * A geometry's morph targets as {@link MorphData} (relative deltas in its vertex order, what
 * `deformer.setMorphTargets` takes), or null when it has none. Throws GcsError NON_FINITE as
 * checkMorphTargets does, INVALID_ARGUMENT for a geometry that is not one.
 */
export function morphData(geometry: THREE.BufferGeometry): MorphData | null {
  checkMethods(geometry, 'geometry', 'morphData', ['getAttribute']);
  checkObject(geometry.morphAttributes, 'geometry.morphAttributes', 'morphData');
  const targets = geometry.morphAttributes.position;
  if (!targets || targets.length === 0) return null;
  const base = geometry.getAttribute('position');
  const n = base.count;
  const relative = geometry.morphTargetsRelative;
  const deltas = (list: AnyAttribute[], baseAttr: AnyAttribute | undefined): Float32Array[] =>
    list.map((attr) => {
      const plain = attr as THREE.BufferAttribute;
      // The common glTF case, zero copy: setMorphTargets copies into wasm anyway.
      if (relative && !(attr as THREE.InterleavedBufferAttribute).isInterleavedBufferAttribute && !attr.normalized
        && attr.itemSize === 3 && plain.array instanceof Float32Array && plain.array.length === n * 3) return plain.array;
      const out = new Float32Array(n * 3);
      for (let i = 0; i < Math.min(n, attr.count); i++) {
        out[3 * i] = attr.getX(i) - (relative || !baseAttr ? 0 : baseAttr.getX(i));
        out[3 * i + 1] = attr.getY(i) - (relative || !baseAttr ? 0 : baseAttr.getY(i));
        out[3 * i + 2] = attr.getZ(i) - (relative || !baseAttr ? 0 : baseAttr.getZ(i));
      }
      return out;
    });
  const positions = deltas(targets, base);
  const normalTargets = geometry.morphAttributes.normal;
  const normalBase = geometry.getAttribute('normal');
  const normals = normalTargets && normalTargets.length === targets.length && normalBase ? deltas(normalTargets, normalBase) : null;
  const maxDelta = new Float32Array(positions.length);
  positions.forEach((d, t) => {
    let m = 0;
    for (let i = 0; i < d.length; i += 3) m = Math.max(m, d[i] * d[i] + d[i + 1] * d[i + 1] + d[i + 2] * d[i + 2]);
    maxDelta[t] = Math.sqrt(m);
  });
  return { positions, normals, maxDelta };
}
