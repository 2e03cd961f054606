// Not in a fresh app: the test's other pages, written by tests/browser/app.test.ts from index.html
// and built beside it: three.js's own skinning (reference.html) and the README's WebGPURenderer
// example (webgpu.html).
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vite';

const page = (name: string) => fileURLToPath(new URL(name, import.meta.url));

export default defineConfig({
  build: { rolldownOptions: { input: { main: page('index.html'), reference: page('reference.html'), webgpu: page('webgpu.html') } } },
});
