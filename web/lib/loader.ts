// Instantiates the standalone gcs-skin.wasm (no emscripten JS glue) in node, vitest and browsers.
import { checkCoreExports } from './core-check.js';
import { UNSIGNED_RESULTS, type CoreFunctions } from './boundary.generated.js';

export { UNSIGNED_RESULTS };

/** Where to find the wasm binary: a URL or path, its bytes, or a compiled module. */
export type WasmSource = URL | string | ArrayBuffer | Uint8Array | WebAssembly.Module;

/**
 * The raw exports of the core: its functions as gcs_skin.h declares them (CoreFunctions, generated
 * from the header by scripts/gen-boundary.mjs), its memory and its initialiser.
 */
export interface CoreExports extends CoreFunctions {
  memory: WebAssembly.Memory;
  _initialize(): void;
}

const isNode = typeof process !== 'undefined' && !!process.versions?.node && typeof window === 'undefined';

async function readBytes(source: URL | string): Promise<ArrayBuffer | Uint8Array> {
  const url = typeof source === 'string' ? new URL(source, isNode ? `file://${process.cwd()}/` : location.href) : source;
  if (url.protocol === 'file:') {
    const fs = await import(/* @vite-ignore */ 'node:fs/promises');
    const { fileURLToPath } = await import(/* @vite-ignore */ 'node:url');
    return fs.readFile(fileURLToPath(url));
  }
  const response = await fetch(url);
  if (!response.ok) throw new Error(`HTTP ${response.status} for ${url}`);
  return response.arrayBuffer();
}

/** Compiles and instantiates the core. Throws a plain Error when the binary cannot be had. */
export async function instantiateCore(source?: WasmSource): Promise<CoreExports> {
  let module: WebAssembly.Module;
  if (source instanceof WebAssembly.Module) {
    module = source;
  } else if (source instanceof ArrayBuffer || source instanceof Uint8Array) {
    module = await WebAssembly.compile(source as BufferSource);
  } else {
    const bytes = await readBytes(source ?? new URL('./gcs-skin.wasm', import.meta.url));
    module = await WebAssembly.compile(bytes as BufferSource);
  }
  let exports: CoreExports | undefined;
  const imports = {
    // Memory growth is noticed lazily: every view is checked against memory.buffer before use.
    env: { emscripten_notify_memory_growth: () => {} },
    wasi_snapshot_preview1: {
      proc_exit: (code: number) => {
        throw new Error(`gcs-skin core aborted (exit ${code})`);
      },
    },
  };
  const instance = await WebAssembly.instantiate(module, imports);
  checkCoreExports(instance.exports);
  exports = unsignedResults(instance.exports as unknown as CoreExports);
  exports._initialize();
  return exports;
}

// Functions whose result is a pointer or a uint32 (UNSIGNED_RESULTS, generated from the header):
// wasm returns i32, which JavaScript reads as signed, so above 2 GiB of memory a pointer would come
// back negative (and typed-array views on it throw RangeError). `>>> 0` reads it as the unsigned
// value the C API means.
function unsignedResults(raw: CoreExports): CoreExports {
  const core = { ...raw } as CoreExports;
  const table = core as unknown as Record<string, (...args: number[]) => number>;
  const source = raw as unknown as Record<string, (...args: number[]) => number>;
  for (const name of UNSIGNED_RESULTS) {
    const f = source[name];
    table[name] = (...args: number[]) => f(...args) >>> 0;
  }
  return core;
}
