// How many joint influences the character's skin has: the readout says it, and the three.js LBS
// view says what it drops (three's skinning reads skinIndex/skinWeight, the first four; GLTFLoader
// keeps JOINTS_1/WEIGHTS_1 as joints_1/weights_1, which gcs-skin reads: up to 8). Counted once per load.
import type * as THREE from 'three';

export interface InfluenceCount {
  /** Most influences (weights > 0) of any vertex, over every skinned mesh. */
  most: number;
  /** Vertices with more than 4: what three's own skinning drops influences 5–8 of. */
  overFour: number;
}

export function countInfluences(sources: readonly THREE.SkinnedMesh[]): InfluenceCount {
  let most = 0, overFour = 0;
  for (const mesh of sources) {
    const sets = [mesh.geometry.getAttribute('skinWeight'), mesh.geometry.getAttribute('weights_1')].filter((a) => a);
    const count = sets[0]?.count ?? 0;
    for (let v = 0; v < count; v++) {
      let n = 0;
      for (const set of sets) for (let k = 0; k < set.itemSize; k++) if (set.getComponent(v, k) > 0) n++;
      most = Math.max(most, n);
      if (n > 4) overFour++;
    }
  }
  return { most, overFour };
}
