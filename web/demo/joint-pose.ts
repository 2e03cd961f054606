// The joint close-up's pose: a character's knees and elbows (gcs-skin/measure's findHinges, on the
// skinned mesh that has them), one of them bent alone from the bind pose by setting the bones, and
// the joint's figures (JointProbe) for a deformer at that bend.
import * as THREE from 'three';
import type { Deformer, RigInput } from '../lib/index.js';
import { rigInputFromSkinnedMesh } from '../lib/three.js';
import { JointProbe, findHinges, type BodyFrame, type Hinge, type JointFigures } from '../lib/measure.js';

/** The mesh the joints were found on, its rig input, what was found, and a probe per joint (made on first use). */
export interface JointRig {
  mesh: THREE.SkinnedMesh;
  input: RigInput;
  hinges: Hinge[];
  frame: BodyFrame | null;
  notes: string[];
  probes: Map<Hinge, JointProbe>;
}

/** Of the character's skinned meshes, the one where the most knees and elbows are found (the larger on a tie). */
export function findJointRig(sources: readonly THREE.SkinnedMesh[]): JointRig {
  let best: JointRig | null = null;
  for (const mesh of sources) {
    const input = rigInputFromSkinnedMesh(mesh);
    const found = findHinges(input, mesh.skeleton.bones.map((b) => b.name));
    const rig = { mesh, input, hinges: found.hinges, frame: found.frame, notes: found.notes, probes: new Map() };
    const size = (r: JointRig) => r.input.positions.length;
    if (!best || rig.hinges.length > best.hinges.length || (rig.hinges.length === best.hinges.length && size(rig) > size(best))) best = rig;
  }
  if (!best) throw new Error('no skinned mesh');
  return best;
}

/** The joint's figures at `degrees` for a deformer built from `rig.mesh` (leaves it posed there; the next update() re-poses it). */
export function jointFigures(rig: JointRig, hinge: Hinge, deformer: Deformer, degrees: number): JointFigures {
  let probe = rig.probes.get(hinge);
  if (!probe) rig.probes.set(hinge, (probe = new JointProbe(rig.input, hinge, [degrees])));
  return probe.measure(deformer, [degrees])[0];
}

const m = new THREE.Matrix4(), turn = new THREE.Matrix4(), world = new THREE.Matrix4(), local = new THREE.Matrix4();
const axis = new THREE.Vector3();

/**
 * Poses the skeleton of `rig.mesh` so that its skin matrices are the bind pose with `hinge.joint`
 * (and what hangs off it) turned by `degrees` about the hinge — what measure's bendSkin gives, so
 * the pictures and the figures show the same pose. Each bone's world matrix is set from
 * S_j = bindMatrixInverse · world_j · boneInverse_j · bindMatrix, then its local transform from its
 * parent's. Every skinned mesh on this skeleton follows.
 */
export function poseBend(rig: JointRig, hinge: Hinge | null, degrees: number): void {
  const { mesh } = rig;
  const { bones, boneInverses } = mesh.skeleton;
  mesh.updateMatrixWorld(true);
  // world_j = bindMatrixInverse⁻¹ · M_j · bindMatrix⁻¹ · boneInverse_j⁻¹, M_j the mesh-space turn or I.
  const below = new Set<number>();
  if (hinge) {
    for (let j = 0; j < bones.length; j++)
      for (let k: THREE.Object3D | null = bones[j]; k; k = k.parent) if (k === bones[hinge.joint]) { below.add(j); break; }
    const [cx, cy, cz] = hinge.centre;
    turn.makeTranslation(cx, cy, cz)
      .multiply(m.makeRotationAxis(axis.fromArray(hinge.axis), THREE.MathUtils.degToRad(degrees)))
      .multiply(m.makeTranslation(-cx, -cy, -cz));
  }
  const worlds = bones.map((_, j) => {
    const w = new THREE.Matrix4().copy(mesh.bindMatrixInverse).invert();
    if (below.has(j)) w.multiply(turn);
    return w.multiply(m.copy(mesh.bindMatrix).invert()).multiply(m.copy(boneInverses[j]).invert());
  });
  const index = new Map(bones.map((b, j) => [b as THREE.Object3D, j]));
  bones.forEach((bone, j) => {
    const p = bone.parent ? index.get(bone.parent) : undefined;
    world.copy(p !== undefined ? worlds[p] : bone.parent ? bone.parent.matrixWorld : m.identity());
    local.copy(world).invert().multiply(worlds[j]);
    local.decompose(bone.position, bone.quaternion, bone.scale);
  });
  let root: THREE.Object3D = mesh;
  while (root.parent) root = root.parent;
  root.updateMatrixWorld(true);
}
