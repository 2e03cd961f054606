// Framing: how far back a camera must stand to see a whole box, used by the comparison views
// (one character) and the crowd (all of them).
import * as THREE from 'three';

const x = new THREE.Vector3(), y = new THREE.Vector3(), corner = new THREE.Vector3(), centre = new THREE.Vector3();

/**
 * The distance from the box's centre, along `direction` (unit, from the centre towards the
 * camera), at which every corner lies inside a frustum of half-angle tangents `tanH` × `tanV`.
 */
export function distanceToFit(box: THREE.Box3, direction: THREE.Vector3, tanH: number, tanV: number): number {
  x.set(0, 1, 0).cross(direction).normalize();
  y.crossVectors(direction, x);
  box.getCenter(centre);
  let distance = 0;
  for (let i = 0; i < 8; i++) {
    corner.set(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z).sub(centre);
    const depth = corner.dot(direction);
    distance = Math.max(distance, depth + Math.abs(corner.dot(x)) / tanH, depth + Math.abs(corner.dot(y)) / tanV);
  }
  return distance;
}
