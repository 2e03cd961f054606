// A shared character written with 8 influences per vertex (JOINTS_1/WEIGHTS_1) by @gltf-transform:
// the file the glTF readers, GcsCharacter and the GPU tests read (node only).
import { NodeIO } from '@gltf-transform/core';
import { overFour, spreadWeights } from './influences.js';

/**
 * Writes `out`: the glTF `source` with every skinned primitive's weights spread (spreadWeights) into
 * JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1, and its textures dropped (three's GLTFLoader cannot
 * decode images in node). Returns the vertices written and how many have more than 4 influences.
 */
export async function eightInfluenceGlb(source: string, out: string): Promise<{ vertices: number; overFour: number }> {
  const io = new NodeIO();
  const doc = await io.read(source);
  const root = doc.getRoot();
  for (const t of root.listTextures()) t.dispose();
  let vertices = 0, over = 0;
  for (const node of root.listNodes()) {
    const skin = node.getSkin(), mesh = node.getMesh();
    if (!skin || !mesh) continue;
    const list = skin.listJoints();
    const parents = list.map((j) => list.indexOf(j.getParentNode()!));
    for (const prim of mesh.listPrimitives()) {
      const j0 = prim.getAttribute('JOINTS_0'), w0 = prim.getAttribute('WEIGHTS_0');
      if (!j0 || !w0) continue;
      const n = j0.getCount(), je: number[] = [], we: number[] = [];
      const joints = new Uint32Array(4 * n), weights = new Float32Array(4 * n);
      for (let v = 0; v < n; v++) { j0.getElement(v, je); w0.getElement(v, we); joints.set(je, 4 * v); weights.set(we, 4 * v); }
      const spread = spreadWeights(joints, weights, parents, n);
      for (let set = 0; set < 2; set++) {
        const js = new Uint16Array(4 * n), ws = new Float32Array(4 * n);
        for (let v = 0; v < n; v++) for (let c = 0; c < 4; c++) { js[4 * v + c] = spread.joints[8 * v + 4 * set + c]; ws[4 * v + c] = spread.weights[8 * v + 4 * set + c]; }
        prim.setAttribute(`JOINTS_${set}`, doc.createAccessor().setType('VEC4').setArray(js).setBuffer(j0.getBuffer()));
        prim.setAttribute(`WEIGHTS_${set}`, doc.createAccessor().setType('VEC4').setArray(ws).setBuffer(j0.getBuffer()));
      }
      vertices += n;
      over += overFour({ positions: new Float32Array(3 * n), indices: [], joints: spread.joints, weights: spread.weights, influences: 8, parents, inverseBindMatrices: [] });
    }
  }
  await io.write(out, doc);
  return { vertices, overFour: over };
}
