// The committed core is a standalone module: it must import nothing a plain
// WebAssembly.instantiate cannot give (printf or an active assert() pull in WASI file calls).
import { expect, test } from 'vitest';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

test('gcs-skin.wasm imports only memory-growth notification and proc_exit', () => {
  const bytes = readFileSync(fileURLToPath(new URL('../../web/lib/gcs-skin.wasm', import.meta.url)));
  const imports = WebAssembly.Module.imports(new WebAssembly.Module(bytes)).map((i) => `${i.module}.${i.name}`).sort();
  expect(imports).toEqual(['env.emscripten_notify_memory_growth', 'wasi_snapshot_preview1.proc_exit']);
});
