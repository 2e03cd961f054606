// Draco data against the glTF that holds it, before any decoder runs (the CLI's and the demo's
// alike): each KHR_draco_mesh_compression primitive's bitstream header must declare the triangles
// and points its accessors declare (which the validator has bounded by LIMITS), so a decoder never
// works on a geometry larger than the file says. Run after validateGltfJson (references and
// buffer view ranges are then known to be sound).
import { GltfError, n } from './error.js';
import type { BufferData, GltfJson } from './json.js';
import { readDracoCounts } from './draco-header.js';
import { shownName } from './shown-name.js';

/** Throws a BAD_DATA GltfError when a primitive's Draco header disagrees with its accessors. */
export function checkDracoCounts(json: GltfJson, buffers: readonly (BufferData | undefined)[], file: string): void {
  const meshes: GltfJson[] = Array.isArray(json.meshes) ? json.meshes : [];
  meshes.forEach((mesh, mi) => (mesh.primitives as GltfJson[]).forEach((p, pi) => {
    const draco = p.extensions?.KHR_draco_mesh_compression;
    if (!draco) return;
    const where = `/meshes/${mi}/primitives/${pi}/extensions/KHR_draco_mesh_compression`;
    const prim = `mesh ${mi}${typeof mesh.name === 'string' && mesh.name ? ` '${shownName(mesh.name)}'` : ''} primitive ${pi}`;
    const bad = (what: string) => new GltfError('BAD_DATA', file, where, `${file}: the Draco data of ${prim} ${what}`);
    const view = json.bufferViews[draco.bufferView];
    const data = buffers[view.buffer]?.bytes;
    if (!data) return; // an extension's buffer with no data: nothing to decode
    const offset = view.byteOffset ?? 0;
    const counts = readDracoCounts(data.subarray(offset, offset + view.byteLength));
    if (typeof counts === 'string') throw bad(`cannot be decoded: ${counts}`);
    const vertices: number = json.accessors[Object.values(p.attributes as Record<string, number>)[0]].count;
    const indices: number | undefined = p.indices === undefined ? undefined : json.accessors[p.indices].count;
    const corners = counts.kind === 'mesh' ? 3 * counts.faces : counts.points;
    if (indices !== undefined ? corners !== indices : counts.kind === 'mesh' && corners !== vertices)
      throw bad(`declares ${n(counts.faces)} triangles where its ${indices !== undefined ? `indices declare ${n(indices / 3)}` : `${n(vertices)} vertices make ${n(vertices / 3)}`}`);
    if (counts.exactPoints ? counts.points !== vertices : counts.points > Math.max(vertices, corners))
      throw bad(`declares ${n(counts.points)} vertices where its accessors declare ${n(vertices)}`);
  }));
}
