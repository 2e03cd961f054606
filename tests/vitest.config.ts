import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vitest/config';

const lib = fileURLToPath(new URL('../web/lib/', import.meta.url));

// Node unit tests. Browser tests (tests/browser) have their own config: they need a built demo.
export default defineConfig({
  resolve: {
    // packages/cli/src imports the library by its package name; the tests import web/lib's sources:
    // one copy of the library in a test (a GcsError is the same class either way). The installed
    // packages are tested from their tarballs (tests/package.test.ts, tests/clone.test.ts).
    alias: [
      { find: /^gcs-skin$/, replacement: `${lib}index.ts` },
      { find: /^gcs-skin\/human$/, replacement: `${lib}human/index.ts` },
      { find: /^gcs-skin\/(three|gpu|crowd|webgpu|measure|gltf)$/, replacement: `${lib}$1.ts` },
    ],
  },
  test: {
    include: ['tests/**/*.test.ts'],
    exclude: ['tests/browser/**', 'tests/.tmp/**', 'node_modules/**'],
    testTimeout: 120000,
    hookTimeout: 120000,
  },
});
