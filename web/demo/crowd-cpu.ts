// The crowd page's CPU backend: a GCS deformer and a mesh per character, as GcsCharacter does, and
// each character's walk (which baked clip, its phase and speed).
import * as THREE from 'three';
import type { GcsDeformer, Rig } from '../lib/index.js';
import type { BakedClip } from '../lib/crowd.js';

/** One character's animation state: which baked clip, its phase and speed. */
export interface Walker {
  clip: number;
  phase: number;
  speed: number;
}

/** The CPU backend: a GCS deformer and a mesh per character (vertex buffers uploaded each frame). */
export class CpuCrowd {
  readonly group = new THREE.Group();
  readonly deformers: GcsDeformer[] = [];
  private readonly scratch: Float32Array;
  constructor(rig: Rig, count: number, material: THREE.Material, smooth: boolean) {
    this.scratch = new Float32Array(rig.jointCount * 16);
    for (let i = 0; i < count; i++) {
      const d = rig.buildGcs({ smooth });
      this.deformers.push(d);
      const g = new THREE.BufferGeometry();
      g.setIndex(new THREE.BufferAttribute(d.indices, 1));
      g.setAttribute('position', new THREE.BufferAttribute(d.positions, 3).setUsage(THREE.DynamicDrawUsage));
      g.setAttribute('normal', new THREE.BufferAttribute(d.normals, 3).setUsage(THREE.DynamicDrawUsage));
      const mesh = new THREE.Mesh(g, material);
      mesh.frustumCulled = false;
      this.group.add(mesh);
    }
  }
  pose(i: number, clip: BakedClip, time: number): void {
    const n = clip.jointCount * 16;
    let f = Math.floor(time * clip.fps) % clip.frames;
    if (f < 0) f += clip.frames;
    const src = clip.data, s = f * n, dst = this.scratch;
    for (let k = 0; k < n; k++) dst[k] = src[s + k];
    const d = this.deformers[i];
    d.deform(dst);
    const g = (this.group.children[i] as THREE.Mesh).geometry;
    const p = g.getAttribute('position') as THREE.BufferAttribute, nrm = g.getAttribute('normal') as THREE.BufferAttribute;
    const pos = d.positions, nor = d.normals; // views re-created after memory growth
    if (p.array !== pos) p.array = pos;
    if (nrm.array !== nor) nrm.array = nor;
    p.needsUpdate = true;
    nrm.needsUpdate = true;
  }
  dispose(): void {
    for (const d of this.deformers) d.dispose();
    for (const m of this.group.children) (m as THREE.Mesh).geometry.dispose();
    this.group.removeFromParent();
  }
}
