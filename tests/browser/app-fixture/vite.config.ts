// Not in a fresh app: the test's second page, three.js's own skinning (reference.html, written by
// tests/browser/app.test.ts from index.html), built beside index.html.
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vite';

const page = (name: string) => fileURLToPath(new URL(name, import.meta.url));

export default defineConfig({
  build: { rolldownOptions: { input: { main: page('index.html'), reference: page('reference.html') } } },
});
