// The decoders of compressed glTF for three's GLTFLoader, as a page that ships such files sets
// them up (README, "Compressed glTF"): DRACOLoader (KHR_draco_mesh_compression), KTX2Loader
// (KHR_texture_basisu) and meshopt's MeshoptDecoder (EXT_meshopt_compression). Each is made on the
// first file that needs it and kept; Draco's wasm comes from the page's own decoders/ folder
// (decoder-files.ts), Basis's is KTX2Loader's own, which the build emits beside the page's code
// (KTX2Loader names it with new URL(…, import.meta.url)): never another origin.
import type * as THREE from 'three';
import type { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import type { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import type { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import type { DemoRenderer } from './renderer.js';

type MeshoptDecoder = Parameters<GLTFLoader['setMeshoptDecoder']>[0];

let draco: Promise<DRACOLoader> | undefined;
let ktx2: Promise<KTX2Loader> | undefined;
let meshopt: Promise<MeshoptDecoder> | undefined;

/** The page's folder of decoder files (built beside index.html). */
const decoderUrl = (path: string) => new URL(`decoders/${path}`, document.baseURI).href;

/**
 * Gives `loader` the decoders the extensions in `used` need; `manager` is the guarded manager of
 * the page's loads (it fetches the decoders' files and KTX2 textures).
 */
export async function addDecoders(loader: GLTFLoader, used: readonly string[], renderer: DemoRenderer, manager: THREE.LoadingManager): Promise<void> {
  if (used.includes('KHR_draco_mesh_compression')) {
    draco ??= import('three/addons/loaders/DRACOLoader.js').then(({ DRACOLoader }) =>
      new DRACOLoader(manager).setDecoderPath({ js: decoderUrl('draco/draco_wasm_wrapper.js'), wasm: decoderUrl('draco/draco_decoder.wasm') }));
    loader.setDRACOLoader(await draco);
  }
  if (used.includes('KHR_texture_basisu')) {
    ktx2 ??= import('three/addons/loaders/KTX2Loader.js').then(({ KTX2Loader }) =>
      new KTX2Loader(manager).detectSupport(renderer as THREE.WebGLRenderer)); // its default transcoder: bundled, one copy
    loader.setKTX2Loader(await ktx2);
  }
  if (used.includes('EXT_meshopt_compression')) {
    meshopt ??= import('three/addons/libs/meshopt_decoder.module.js').then(async ({ MeshoptDecoder }) => {
      await MeshoptDecoder.ready;
      return MeshoptDecoder as MeshoptDecoder;
    });
    loader.setMeshoptDecoder(await meshopt);
  }
}

/** What a decoder's failure says on the page: which compression of the file does not decode. */
export function decoderFailure(used: readonly string[]): string | null {
  const names = [
    used.includes('KHR_draco_mesh_compression') && 'Draco',
    used.includes('EXT_meshopt_compression') && 'meshopt',
    used.includes('KHR_texture_basisu') && 'KTX2',
  ].filter(Boolean);
  return names.length ? `its ${names.join(' or ')} data does not decode` : null;
}
