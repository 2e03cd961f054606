// Compressed glTF made in the tests (no checked-in binaries), as a three.js user's pipeline makes
// them: @gltf-transform with draco() (draco3dgltf's encoder), meshopt() (meshoptimizer's) and a
// KTX2 texture (KHR_texture_basisu) encoded with Basis Universal by ktx2-encoder (ETC1S), all
// offline. Used by tests/cli/compressed.test.ts and the demo's browser tests.
import { NodeIO, type Document } from '@gltf-transform/core';
import { EXTMeshoptCompression, KHRDracoMeshCompression, KHRMeshQuantization, KHRTextureBasisu } from '@gltf-transform/extensions';
import { draco, meshopt } from '@gltf-transform/functions';
import { MeshoptDecoder, MeshoptEncoder } from 'meshoptimizer';

/** draco3dgltf: CommonJS without types (createEncoderModule / createDecoderModule), imported by name. */
const DRACO_MODULE = 'draco3dgltf';

let io: Promise<NodeIO> | undefined;

/** A NodeIO that reads and writes the three geometry compressions and KTX2 textures, quietly. */
export function compressionIO(): Promise<NodeIO> {
  io ??= (async () => {
    await Promise.all([MeshoptEncoder.ready, MeshoptDecoder.ready]);
    const draco3d = (await import(DRACO_MODULE)).default;
    const quiet = { debug() {}, info() {}, warn() {}, error: (t: string) => console.error(t), verbosity: 0 };
    return new NodeIO()
      .setLogger(quiet as never)
      .registerExtensions([KHRMeshQuantization, EXTMeshoptCompression, KHRDracoMeshCompression, KHRTextureBasisu])
      .registerDependencies({
        'meshopt.encoder': MeshoptEncoder, 'meshopt.decoder': MeshoptDecoder,
        'draco3d.encoder': await draco3d.createEncoderModule(), 'draco3d.decoder': await draco3d.createDecoderModule(),
      });
  })();
  return io;
}

/**
 * A `size`² KTX2 texture, Basis Universal ETC1S (the BasisLZ supercompressed kind three's
 * KTX2Loader transcodes in its worker), of a pattern of red-orange stripes. The encoder's own
 * progress lines (it prints them whatever its debug flag) are kept off the test output.
 */
export async function ktx2Texture(size = 16): Promise<Uint8Array> {
  const { encodeToKTX2 } = await import('ktx2-encoder');
  const rgba = new Uint8Array(4 * size * size);
  for (let i = 0; i < size * size; i++) rgba.set([200 + 40 * ((i >> 2) & 1), 90, 60, 255], 4 * i);
  const log = console.log;
  const write = process.stdout.write;
  console.log = () => {};
  process.stdout.write = (() => true) as typeof process.stdout.write;
  try {
    return await encodeToKTX2(new Uint8Array(0), { isUASTC: false, generateMipmap: false, imageDecoder: async () => ({ width: size, height: size, data: rgba }) });
  } finally {
    console.log = log;
    process.stdout.write = write;
  }
}

export type Compression = 'draco' | 'draco-sequential' | 'meshopt' | 'ktx2';

/** `glb` compressed one way, as a .glb: Draco or meshopt geometry, or a KTX2 base colour texture on every material. */
export async function compressGlb(glb: Uint8Array, how: Compression): Promise<Uint8Array> {
  const io = await compressionIO();
  const doc = await io.readBinary(glb);
  await compressDocument(doc, how);
  return io.writeBinary(doc);
}

/** Compresses `doc` in place (see compressGlb). */
export async function compressDocument(doc: Document, how: Compression): Promise<void> {
  if (how === 'draco') await doc.transform(draco());
  else if (how === 'draco-sequential') await doc.transform(draco({ method: 'sequential' }));
  else if (how === 'meshopt') await doc.transform(meshopt({ encoder: MeshoptEncoder }));
  else {
    doc.createExtension(KHRTextureBasisu).setRequired(true);
    const texture = doc.createTexture('stripes').setImage(await ktx2Texture()).setMimeType('image/ktx2').setURI('stripes.ktx2');
    for (const material of doc.getRoot().listMaterials()) material.setBaseColorTexture(texture);
  }
}
