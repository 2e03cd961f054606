import { defineConfig } from 'vitest/config';

// Node unit tests. Browser tests (tests/browser) have their own config: they need a built demo.
export default defineConfig({
  test: {
    include: ['tests/**/*.test.ts'],
    exclude: ['tests/browser/**', 'tests/.tmp/**', 'node_modules/**'],
    testTimeout: 120000,
    hookTimeout: 120000,
  },
});
