// The wasm boundary, one statement: wasm/include/gcs_skin.h. The TypeScript side (every function
// with its arguments, unsigned results, error codes, enums, limits, defaults, packed layouts, the
// settings struct) is generated from it (scripts/gen-boundary.mjs → web/lib/boundary.generated.ts,
// committed). Here: the committed file is what the header gives today (any drift fails, argument
// counts included), the binary exports what the header declares with as many arguments, the
// header's comments name only what exists, and the defaults the docs state are the header's.
// Also: an unknown error code from the core is an error of its own, and a core of another version
// is refused at load.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { beforeAll, describe, expect, test } from 'vitest';
import {
  CLASSIC_DEFAULTS, CRITERIA, GCS_DEFAULTS, GcsError, initGcsSkin, version, type GcsSkin, type RigInput,
} from '../../web/lib/index.js';
import {
  ARGUMENT_COUNTS, GCS_MAX_VERTICES, GCS_VERSION, GcsSettingsBytes, GcsStat, writeGcsSettings, type GcsSettings,
} from '../../web/lib/boundary.generated.js';
import { LIMITS as GLTF_LIMITS } from '../../web/lib/gltf/limits.js';
import { generateBoundary, GENERATED, HEADER, parseHeader } from '../../scripts/gen-boundary.mjs';
import { makeTube } from '../helpers/cylinder.js';

const ROOT = join(__dirname, '../..');
const header = readFileSync(HEADER, 'utf8');

describe('the TypeScript side is generated from gcs_skin.h', () => {
  test('the committed boundary.generated.ts is what the header gives (npm run gen:boundary rewrites it)', () => {
    expect(readFileSync(GENERATED, 'utf8')).toBe(generateBoundary(header));
  });

  test('drift is caught: an argument added to a function, a renumbered enum, a changed limit', () => {
    const committed = readFileSync(GENERATED, 'utf8');
    const drifted = [
      header.replace('GcsDeformer* gcs_build_gcs(const GcsRig* rig, const GcsSettings* settings);',
        'GcsDeformer* gcs_build_gcs(const GcsRig* rig, const GcsSettings* settings, int extra);'),
      header.replace('GCS_STAT_ADJUSTED_SECTIONS = 3', 'GCS_STAT_ADJUSTED_SECTIONS = 4'),
      header.replace('#define GCS_MAX_SECTIONS 256', '#define GCS_MAX_SECTIONS 255'),
    ];
    for (const text of drifted) expect(text).not.toBe(header);
    expect(generateBoundary(drifted[0])).toMatch(/gcs_build_gcs: 3,/);
    for (const text of drifted) expect(generateBoundary(text)).not.toBe(committed);
  });

  test('what the generator cannot read is an error, not a silent gap', () => {
    expect(() => generateBoundary(`${header}\n#define GCS_ODD "text"\n`)).toThrow(/cannot read #define GCS_ODD/);
    expect(() => generateBoundary(`${header}\ntypedef struct GcsOdd { double x; } GcsOdd;\n`)).toThrow(/cannot lay out 'double x'/);
    expect(() => generateBoundary(`${header}\ntypedef enum GcsOdd { GCS_ODD_A, GCS_ODD_B = 1 } GcsOdd;\n`)).toThrow(/enum GcsOdd/);
  });

  test('the binary exports every declared function, each with the declared number of arguments', async () => {
    const { functions } = parseHeader(header);
    expect(functions.length).toBeGreaterThan(40);
    const module = new WebAssembly.Module(readFileSync(join(ROOT, 'web/lib/gcs-skin.wasm')));
    const exported = WebAssembly.Module.exports(module).filter((e) => e.kind === 'function' && e.name.startsWith('gcs_')).map((e) => e.name);
    expect(exported.sort()).toEqual(functions.map((f) => f.name).sort());
    const instance = await WebAssembly.instantiate(module, {
      env: { emscripten_notify_memory_growth: () => {} }, wasi_snapshot_preview1: { proc_exit: () => {} },
    });
    const raw = instance.exports as Record<string, unknown>;
    for (const f of functions) {
      expect((raw[f.name] as (...a: number[]) => number).length, f.name).toBe(f.args.length);
      expect(ARGUMENT_COUNTS[f.name as keyof typeof ARGUMENT_COUNTS], f.name).toBe(f.args.length);
    }
  });

  test("the header's comments name only what it declares, and document every statistic", () => {
    const code = header.replace(/\/\*[\s\S]*?\*\//g, '');
    const comments = [...header.matchAll(/\/\*[\s\S]*?\*\//g)].map((m) => m[0]).join('\n');
    const declared = new Set(code.match(/\b(GCS_\w+|gcs_\w+|Gcs\w+)\b/g));
    const named = new Set(comments.match(/\b(GCS_\w*[A-Z0-9]|gcs_\w*[a-z0-9]|Gcs[A-Z]\w*)\b/g));
    expect([...named].filter((n) => !declared.has(n))).toEqual([]);
    const statDocs = /\* Per-deformer statistics[\s\S]*?\*\//.exec(header)![0];
    for (const [name] of parseHeader(header).enums.find((e) => e.name === 'GcsStat')!.values) expect(statDocs, name).toContain(name);
  });

  test('the limits the glTF reader shares with the core are the same', () => {
    expect(GLTF_LIMITS.vertices).toBe(GCS_MAX_VERTICES);
    const [major, minor, patch] = version().split('.').map(Number);
    expect(major * 10000 + minor * 100 + patch).toBe(GCS_VERSION);
    expect(version()).toBe(JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')).version);
  });

  test("the defaults the library's docs state are the header's", () => {
    const index = readFileSync(join(ROOT, 'web/lib/index.ts'), 'utf8');
    const stated = [...index.matchAll(/Default `(GCS|CLASSIC)_DEFAULTS\.(\w+)` \(([^,)]+)/g)];
    expect(stated.length).toBe(8); // every option but smooth, whose default depends on the criterion
    const defaults: Record<string, Record<string, unknown>> = { GCS: GCS_DEFAULTS, CLASSIC: CLASSIC_DEFAULTS };
    for (const [, group, key, value] of stated) expect(String(defaults[group][key]), `${group}_DEFAULTS.${key}`).toBe(value.replace(/'/g, ''));
  });
});

describe('the core at run time', () => {
  let gcs: GcsSkin;
  beforeAll(async () => {
    gcs = await initGcsSkin();
  });

  test("the binary's gcs_version() is the header's GCS_VERSION", () => {
    expect(gcs.core.gcs_version()).toBe(GCS_VERSION);
  });

  test('smooth left out is the default the library documents, under every criterion (the core resolves it)', () => {
    const rig = gcs.createRig(makeTube().input);
    for (const criterion of CRITERIA) {
      const d = rig.buildGcs({ criterion });
      expect(d.blendOther() !== null, criterion).toBe(GCS_DEFAULTS.smooth(criterion));
      d.dispose();
    }
    rig.dispose();
  });

  test("an error code the wrapper does not know is UNKNOWN_CORE_ERROR, with the core's number and sentence", () => {
    const bad: RigInput = { ...makeTube().input, indices: [0, 1] }; // the core refuses it (LENGTH_MISMATCH)
    const core = gcs.core as unknown as { gcs_last_error_code: () => number };
    const real = core.gcs_last_error_code;
    core.gcs_last_error_code = () => 99;
    try {
      expect(() => gcs.createRig(bad)).toThrow(GcsError);
      try { gcs.createRig(bad); } catch (e) {
        expect((e as GcsError).code).toBe('UNKNOWN_CORE_ERROR');
        expect((e as GcsError).message).toMatch(/error code 99, which gcs-skin \d+\.\d+\.\d+ does not know.*multiple of 3/);
      }
    } finally {
      core.gcs_last_error_code = real;
    }
    expect(GcsError.codeFromNumber(0)).toBe('UNKNOWN_CORE_ERROR'); // a failure reported as GCS_OK
    expect(GcsError.codeFromNumber(7)).toBe('SECTION_COUNT');
    expect(GcsStat.adjustedSections).toBe(3);
  });

  test("the core checks gcs_build_gcs's settings itself (C callers have no wrapper), once", () => {
    const rig = gcs.createRig(makeTube().input);
    const handle = (rig as unknown as { handle: number }).handle;
    const core = gcs.core;
    const ptr = core.gcs_alloc(GcsSettingsBytes);
    const build = (change: Partial<GcsSettings>) => {
      writeGcsSettings(gcs.memory.buffer, ptr, { sections: 6, criterion: 2, influenceWidth: 1, smooth: 1, twistSpread: 0, centres: 0, ...change });
      return core.gcs_build_gcs(handle, ptr);
    };
    const refused = (change: Partial<GcsSettings>) => {
      expect(build(change)).toBe(0);
      return { code: core.gcs_last_error_code(), message: (() => { try { gcs.raise(''); } catch (e) { return (e as Error).message; } })() };
    };
    expect(refused({ sections: 2 })).toEqual({ code: 7, message: expect.stringMatching(/between 3 and 256 .*got 2$/) });
    expect(refused({ sections: 257 })).toEqual({ code: 7, message: expect.stringMatching(/got 257$/) });
    expect(refused({ criterion: 3 })).toEqual({ code: 1, message: expect.stringMatching(/unknown section criterion 3/) });
    expect(refused({ influenceWidth: 0 })).toEqual({ code: 9, message: expect.stringMatching(/influence width must be in \(0, 1\]; got 0/) });
    expect(refused({ smooth: 2 })).toEqual({ code: 1, message: expect.stringMatching(/smooth must be 0, 1 or .*got 2$/) });
    expect(refused({ centres: -1 })).toEqual({ code: 1, message: expect.stringMatching(/centres must be 0 or 1; got 0 and -1$/) });
    expect(core.gcs_build_gcs(handle, 0)).toBe(0);
    expect(core.gcs_last_error_code()).toBe(1);
    const ok = build({ smooth: -1 });
    expect(ok).not.toBe(0);
    core.gcs_deformer_destroy(ok);
    core.gcs_free(ptr);
    rig.dispose();
  });

  test('a core of another version is refused at load (WASM_LOAD, both versions named)', async () => {
    // A hand-made module: memory, _initialize, and gcs_version() returning 99 (version 0.0.99).
    const name = (s: string) => [s.length, ...Buffer.from(s)];
    const exports = [3, ...name('gcs_version'), 0, 0, ...name('_initialize'), 0, 1, ...name('memory'), 2, 0];
    const bytes = new Uint8Array([
      0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00,
      0x01, 0x08, 0x02, 0x60, 0x00, 0x01, 0x7f, 0x60, 0x00, 0x00, // types: () → i32, () → ()
      0x03, 0x03, 0x02, 0x00, 0x01, // functions
      0x05, 0x03, 0x01, 0x00, 0x01, // one page of memory
      0x07, exports.length, ...exports,
      0x0a, 0x0a, 0x02, 0x05, 0x00, 0x41, 0xe3, 0x00, 0x0b, 0x02, 0x00, 0x0b, // i32.const 99; nothing
    ]);
    await expect(initGcsSkin({ wasm: bytes })).rejects.toMatchObject({
      code: 'WASM_LOAD', message: expect.stringMatching(/version 0\.0\.99, but this gcs-skin is \d+\.\d+\.\d+/),
    });
  });
});
