// Where a skin's world matrices come from: the smallest subtree holding a mesh and its bones.
import type * as THREE from 'three';

/** The lowest object that holds the source and all its bones: what update() refreshes. */
export function commonAncestor(objects: THREE.Object3D[]): THREE.Object3D {
  const chain = (o: THREE.Object3D) => {
    const c: THREE.Object3D[] = [];
    for (let p: THREE.Object3D | null = o; p; p = p.parent) c.push(p);
    return c.reverse();
  };
  let common = chain(objects[0]);
  for (const o of objects.slice(1)) {
    const c = chain(o);
    let k = 0;
    while (k < common.length && k < c.length && common[k] === c[k]) k++;
    common = common.slice(0, k);
  }
  if (common.length) return common[common.length - 1];
  // Disjoint graphs: fall back to the source's topmost ancestor (the old behaviour).
  let root = objects[0];
  while (root.parent) root = root.parent;
  return root;
}

/** Brings `object`'s world matrix and its subtree's up to date, its ancestors first. */
export function updateWorld(object: THREE.Object3D): void {
  // updateMatrixWorld, not updateWorldMatrix: SkinnedMesh overrides only the former (attached
  // bind mode refreshes bindMatrixInverse there).
  object.parent?.updateWorldMatrix(true, false);
  object.updateMatrixWorld(true);
}
