// The CPU backend's tangent and velocity tests: a human with tangents, and a WebGPURenderer as a
// mesh's onBeforeRender sees it drawing (with or without a velocity pass).
import * as THREE from 'three/webgpu';
import type { Human } from '../../web/lib/human/index.js';

/** A copy of `human`'s mesh with its own geometry and tangents, in a group. */
export function humanWithTangents(human: Human): { mesh: THREE.SkinnedMesh; group: THREE.Group } {
  const mesh = human.mesh.clone() as THREE.SkinnedMesh;
  mesh.geometry = human.mesh.geometry.clone();
  mesh.geometry.computeTangents();
  const group = new THREE.Group();
  group.add(mesh);
  return { mesh, group };
}

/** What onBeforeRender sees of a WebGPURenderer drawing a velocity pass (or not). */
export const webgpuRenderer = (velocity: boolean) => ({ isWebGPURenderer: true, getMRT: () => (velocity ? { has: (name: string) => name === 'velocity' } : null) });

/** Calls `mesh`'s onBeforeRender as renderer `r` drawing it. */
export function drawWith(mesh: THREE.Mesh, r: unknown): void {
  mesh.onBeforeRender(r as Parameters<THREE.Mesh['onBeforeRender']>[0], new THREE.Scene(), new THREE.PerspectiveCamera(), mesh.geometry, mesh.material as THREE.Material, null as unknown as THREE.Group);
}
