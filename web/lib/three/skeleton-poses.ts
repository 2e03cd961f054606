// The skin matrices of each skeleton, written once a frame (as three.js poses each skeleton once
// per frame, not once per mesh): a character's skins on the same bones (a body, its clothes, its
// eyes) with the same bind matrix read one array. GLTFLoader gives every SkinnedMesh a Skeleton
// object of its own even where they share a glTF skin, so skins match by their bones and inverse
// bind matrices, not by Skeleton object.
import * as THREE from 'three';
import { skinTails, writeSkinMatrices, writeSkinMatricesWithTails } from './skin-matrices.js';

interface Posed {
  bones: readonly THREE.Bone[];
  boneInverses: readonly THREE.Matrix4[];
  bindMatrix: THREE.Matrix4;
  skin: Float32Array;
  /** boneInverse_j · bindMatrix per joint (skinTails), or null: the full product every frame. */
  tails: Float64Array | null;
  frame: number;
}

function sameBones(p: Posed, skeleton: THREE.Skeleton): boolean {
  const { bones, boneInverses } = skeleton;
  if (bones.length !== p.bones.length) return false;
  for (let j = 0; j < bones.length; j++) if (bones[j] !== p.bones[j] || !boneInverses[j].equals(p.boneInverses[j])) return false;
  return true;
}

export class SkeletonPoses {
  private readonly posed: Posed[] = [];
  private readonly bySource = new Map<THREE.SkinnedMesh, Posed>();
  private frame = 0;
  private readonly tmp = new THREE.Matrix4();

  /** A new frame: each skeleton is posed again at its first skinOf. */
  nextFrame(): void {
    this.frame++;
  }

  /**
   * `source`'s skin matrices this frame (J × 16 floats, writeSkinMatrices'): written at the first
   * call for its bones and bind matrix, then the same array. Allocates only the first time a
   * source, or a skeleton, is seen; the bones' inverse bind matrices are read then (the skins' GCS
   * models were built from them), their products with the bind matrix kept (skinTails).
   */
  skinOf(source: THREE.SkinnedMesh): Float32Array {
    let p = this.bySource.get(source);
    if (!p || !p.bindMatrix.equals(source.bindMatrix)) {
      p = this.posed.find((q) => q.bindMatrix.equals(source.bindMatrix) && sameBones(q, source.skeleton));
      if (!p) {
        const { bones, boneInverses } = source.skeleton;
        p = { bones: [...bones], boneInverses: boneInverses.map((m) => m.clone()), bindMatrix: source.bindMatrix.clone(),
          skin: new Float32Array(bones.length * 16), tails: skinTails(source), frame: -1 };
        this.posed.push(p);
      }
      this.bySource.set(source, p);
    }
    if (p.frame !== this.frame) {
      if (p.tails) writeSkinMatricesWithTails(source, p.tails, p.skin, this.tmp);
      else writeSkinMatrices(source, p.skin, 0, this.tmp);
      p.frame = this.frame;
    }
    return p.skin;
  }
}
