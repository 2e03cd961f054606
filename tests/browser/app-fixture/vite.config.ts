// Not in a fresh app: the test's second page, three.js's own skinning (reference.html), built beside index.html.
import { defineConfig } from 'vite';

export default defineConfig({
  build: { rolldownOptions: { input: { main: 'index.html', reference: 'reference.html' } } },
});
