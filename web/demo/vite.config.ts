// Vite config of the demo page: `npm start` (dev server) and `npm run build:demo` (static build).
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vite';
import { decoderFiles } from './decoder-files.js';

const here = fileURLToPath(new URL('.', import.meta.url));
const repo = fileURLToPath(new URL('../..', import.meta.url));

export default defineConfig({
  root: here,
  // Relative asset URLs: the built page works from any folder (GitHub Pages, file servers).
  base: './',
  // Static assets at the repository's top level (public/): the shipped characters (Fox.glb,
  // CesiumMan.glb, RobotExpressive.glb) and their LICENSES.md, copied as they are to the build's root.
  publicDir: fileURLToPath(new URL('../../public', import.meta.url)),
  server: { fs: { allow: [repo] } },
  // Draco's and Basis Universal's decoders, served from the page's own origin (decoder-files.ts).
  plugins: [decoderFiles()],
  // The human character is generated in a module worker (it imports three).
  worker: { format: 'es' },
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    target: 'es2022',
    chunkSizeWarningLimit: 2000,
  },
});
