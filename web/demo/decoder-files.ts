// The compressed-glTF decoders the page loads at run time that no module names (Draco's wasm and
// its JavaScript wrapper, from three's addons), served from the page's own origin: a Vite plugin
// that serves them under decoders/ in dev and writes them into the build. Never a CDN: the page's
// Content-Security-Policy allows no other origin. Basis Universal's transcoder is KTX2Loader's
// default, which Vite emits itself (new URL(…, import.meta.url)); meshopt's decoder is plain
// JavaScript (its wasm inlined) and is bundled like any module.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import type { Plugin } from 'vite';

/** The page's folder for them, relative to the page. */
export const DECODER_FOLDER = 'decoders';

/** URL path under the page's folder → the file in node_modules. */
const FILES: Record<string, string> = {
  'draco/draco_wasm_wrapper.js': 'three/examples/jsm/libs/draco/gltf/draco_wasm_wrapper.js',
  'draco/draco_decoder.wasm': 'three/examples/jsm/libs/draco/gltf/draco_decoder.wasm',
};

export function decoderFiles(): Plugin {
  const require = createRequire(import.meta.url);
  const path = (name: string) => require.resolve(FILES[name]);
  return {
    name: 'gcs-skin-decoder-files',
    configureServer(server) {
      server.middlewares.use((req, res, next) => {
        const name = decodeURIComponent(new URL(req.url ?? '/', 'http://x').pathname).replace(/^.*?\/decoders\//, '');
        if (!req.url?.includes(`/${DECODER_FOLDER}/`) || !(name in FILES)) return next();
        res.setHeader('Content-Type', name.endsWith('.wasm') ? 'application/wasm' : 'text/javascript');
        res.end(readFileSync(path(name)));
      });
    },
    generateBundle() {
      for (const name of Object.keys(FILES))
        this.emitFile({ type: 'asset', fileName: `${DECODER_FOLDER}/${name}`, source: readFileSync(path(name)) });
    },
  };
}
