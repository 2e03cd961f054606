// The mesh a SkinDeformer draws.
import * as THREE from 'three';

/**
 * The output mesh: its geometry is the deformer's output, so raycasts hit the deformed skin.
 * Before a raycast its bounds are made exact (one pass over the positions; the raycast itself
 * walks every triangle), whereas frustum culling uses the per-frame bounds from the bones. An
 * in-place mesh hidden with its source is not deformed, so it is not raycast either.
 */
export class DeformedMesh extends THREE.Mesh<THREE.BufferGeometry, THREE.Material | THREE.Material[]> {
  /** @internal Set by the SkinDeformer that owns the mesh. */
  exactBounds: (() => boolean) | null = null;
  /** @internal GPU backend: the CPU-deformed geometry that raycasts test (the drawn one stays in the bind pose). */
  raycastGeometry: THREE.BufferGeometry | null = null;
  override raycast(raycaster: THREE.Raycaster, intersects: THREE.Intersection[]): void {
    // false: an in-place mesh hidden with its source, not deformed since (stale): no hits.
    if (this.exactBounds && !this.exactBounds()) return;
    const drawn = this.geometry;
    if (this.raycastGeometry) this.geometry = this.raycastGeometry;
    try {
      super.raycast(raycaster, intersects);
    } finally {
      this.geometry = drawn;
    }
  }
}
