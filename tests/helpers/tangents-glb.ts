// A shared character written with MikkTSpace tangents (@gltf-transform's tangents() with the
// mikktspace package), for the normal-mapped tests (node only).
import { NodeIO } from '@gltf-transform/core';
import { tangents, unweld, weld } from '@gltf-transform/functions';
import { generateTangents } from 'mikktspace';

/**
 * Writes `out`: the glTF `source` with MikkTSpace TANGENTs on every primitive (unwelded for
 * MikkTSpace, welded again after), its textures dropped (the tests give it a normal map of their
 * own). Returns the number of vertices that carry a tangent.
 */
export async function tangentGlb(source: string, out: string): Promise<number> {
  const io = new NodeIO();
  const doc = await io.read(source);
  for (const t of doc.getRoot().listTextures()) t.dispose();
  await doc.transform(unweld(), tangents({ generateTangents, overwrite: true }), weld());
  let count = 0;
  for (const mesh of doc.getRoot().listMeshes()) for (const prim of mesh.listPrimitives()) count += prim.getAttribute('TANGENT')?.getCount() ?? 0;
  await io.write(out, doc);
  return count;
}
