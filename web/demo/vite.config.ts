// Vite config of the demo page: `npm start` (dev server) and `npm run build:demo` (static build).
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vite';

const here = fileURLToPath(new URL('.', import.meta.url));
const repo = fileURLToPath(new URL('../..', import.meta.url));

export default defineConfig({
  root: here,
  // Relative asset URLs: the built page works from any folder (GitHub Pages, file servers).
  base: './',
  server: { fs: { allow: [repo] } },
  // The human character is generated in a module worker (it imports three).
  worker: { format: 'es' },
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    target: 'es2022',
    chunkSizeWarningLimit: 2000,
  },
});
