// The wasm boundary, read from the header: wasm/include/gcs_skin.h is the one statement of the C
// API, and what the JavaScript side restates of it (the export table and its unsigned results,
// error codes, enums, limits, texel constants, the version) must say the same. A change to the
// header that the wrapper does not follow fails here. Also: an unknown error code from the core is
// an error of its own, and a core of another version is refused at load.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { beforeAll, describe, expect, test } from 'vitest';
import {
  CLASSIC_LIMITS, CLASSIC_REASONS, CRITERIA, GcsError, GPU_TEXELS_PER_JOINT, GPU_TEXELS_PER_SECTION, initGcsSkin, MAX_INFLUENCES,
  MAX_INSTANCES, MAX_SECTIONS, MIN_SECTIONS, version, type GcsSkin, type RigInput,
} from '../../web/lib/index.js';
import { DEFORMER_KINDS, STATS } from '../../web/lib/core-enums.js';
import { CORE_ERROR_CODES } from '../../web/lib/errors.js';
import { UNSIGNED_RESULTS } from '../../web/lib/loader.js';
import { LIMITS as GLTF_LIMITS } from '../../web/lib/gltf/limits.js';
import { makeTube } from '../helpers/cylinder.js';

const ROOT = join(__dirname, '../..');
const header = readFileSync(join(ROOT, 'wasm/include/gcs_skin.h'), 'utf8');
const code = header.replace(/\/\*[\s\S]*?\*\//g, ''); // the declarations, without the comments

/** `#define GCS_X value` → value (numeric; GCS_VERSION evaluated from its parts). */
function defines(): Map<string, number> {
  const out = new Map<string, number>();
  for (const [, name, value] of code.matchAll(/^#define (GCS_\w+)[ \t]+(.+?)\s*$/gm)) {
    const expr = value.replace(/\b(GCS_\w+)\b/g, (_, n: string) => String(out.get(n) ?? NaN)).replace(/(\d)f\b/g, '$1');
    if (!/^[\d\s.+*()-]+$/.test(expr)) throw new Error(`cannot read #define ${name} ${value}`);
    out.set(name, Function(`return (${expr});`)() as number);
  }
  return out;
}

/** `typedef enum Name { A = 0, B = 1 } Name;` → [[A, 0], [B, 1]]. */
function enumOf(name: string): [string, number][] {
  const body = new RegExp(`typedef enum ${name} \\{([\\s\\S]*?)\\} ${name};`).exec(code)?.[1];
  if (!body) throw new Error(`no enum ${name} in the header`);
  return [...body.matchAll(/(\w+)\s*=\s*(\d+)/g)].map(([, k, v]) => [k, Number(v)]);
}

/** Every function the header declares, with whether its result is a pointer or a uint32_t. */
function functions(): { name: string; unsigned: boolean }[] {
  return [...code.matchAll(/^((?:const\s+)?[A-Za-z_]\w*\s*\**)\s*(gcs_\w+)\s*\(/gm)]
    .map(([, ret, name]) => ({ name, unsigned: ret.includes('*') || ret.trim() === 'uint32_t' }));
}

/** The members of the loader's CoreExports interface (its source). */
function loaderExports(): string[] {
  const loader = readFileSync(join(ROOT, 'web/lib/loader.ts'), 'utf8');
  const body = /export interface CoreExports \{([\s\S]*?)\n\}/.exec(loader)![1];
  return [...body.matchAll(/^\s+(gcs_\w+)\(/gm)].map((m) => m[1]);
}

const sorted = (a: Iterable<string>) => [...a].sort();

describe('the JavaScript side says what gcs_skin.h says', () => {
  test('every function: in the loader, in the binary, unsigned results read as unsigned', () => {
    const declared = functions();
    expect(declared.length).toBeGreaterThan(40);
    expect(sorted(loaderExports())).toEqual(sorted(declared.map((f) => f.name)));
    const wasm = new WebAssembly.Module(readFileSync(join(ROOT, 'web/lib/gcs-skin.wasm')));
    const exported = WebAssembly.Module.exports(wasm).filter((e) => e.kind === 'function' && e.name.startsWith('gcs_')).map((e) => e.name);
    expect(sorted(exported)).toEqual(sorted(declared.map((f) => f.name)));
    expect(sorted(UNSIGNED_RESULTS)).toEqual(sorted(declared.filter((f) => f.unsigned).map((f) => f.name)));
  });

  test('error codes: GcsError by number', () => {
    const entries = enumOf('GcsError');
    expect(CORE_ERROR_CODES.length).toBe(Math.max(...entries.map(([, v]) => v)) + 1);
    for (const [name, n] of entries) expect(CORE_ERROR_CODES[n], name).toBe(name === 'GCS_OK' ? null : name.replace(/^GCS_ERR_/, ''));
  });

  test('enums: criteria, deformer kinds, statistics, classic reasons', () => {
    for (const [name, n] of enumOf('GcsCriterion')) expect(CRITERIA[n], name).toBe(name.replace(/^GCS_CRITERION_/, '').toLowerCase());
    expect(CRITERIA.length).toBe(enumOf('GcsCriterion').length);
    for (const [name, n] of enumOf('GcsDeformerKind')) expect(DEFORMER_KINDS[n], name).toBe(name.replace(/^GCS_KIND_/, '').toLowerCase());
    expect(DEFORMER_KINDS.length).toBe(enumOf('GcsDeformerKind').length);
    const camel = (s: string) => s.toLowerCase().replace(/_(\w)/g, (_, c: string) => c.toUpperCase());
    expect(Object.fromEntries(enumOf('GcsStat').map(([name, n]) => [camel(name.replace(/^GCS_STAT_/, '')), n]))).toEqual(STATS);
    for (const [name, n] of enumOf('GcsClassicReason'))
      expect(CLASSIC_REASONS[n], name).toBe(name.replace(/^GCS_CLASSIC_/, '').toLowerCase().replace(/_/g, '-'));
    expect(CLASSIC_REASONS.length).toBe(enumOf('GcsClassicReason').length);
  });

  test('limits, texel constants and the version: every #define has its JavaScript value', () => {
    const v = version().split('.').map(Number);
    const pkg = JSON.parse(readFileSync(join(ROOT, 'package.json'), 'utf8')).version as string;
    expect(version()).toBe(pkg);
    const js: Record<string, number> = {
      GCS_VERSION_MAJOR: v[0], GCS_VERSION_MINOR: v[1], GCS_VERSION_PATCH: v[2], GCS_VERSION: v[0] * 10000 + v[1] * 100 + v[2],
      GCS_MIN_SECTIONS: MIN_SECTIONS, GCS_MAX_SECTIONS: MAX_SECTIONS, GCS_MAX_INFLUENCES: MAX_INFLUENCES,
      GCS_MAX_VERTICES: GLTF_LIMITS.vertices, GCS_MAX_INSTANCES: MAX_INSTANCES,
      GCS_GPU_TEXELS_PER_SECTION: GPU_TEXELS_PER_SECTION, GCS_GPU_TEXELS_PER_JOINT: GPU_TEXELS_PER_JOINT,
      GCS_CLASSIC_MIN_CONTOURS: CLASSIC_LIMITS.minContours, GCS_CLASSIC_MAX_CONTOURS: CLASSIC_LIMITS.maxContours,
      GCS_CLASSIC_MIN_RAYS: CLASSIC_LIMITS.minRays, GCS_CLASSIC_MAX_RAYS: CLASSIC_LIMITS.maxRays, GCS_CLASSIC_MAX_BULGE: CLASSIC_LIMITS.maxBulge,
    };
    // Checked by the core alone (the wrapper passes them through and reports the core's error).
    const coreOnly = ['GCS_MAX_JOINTS', 'GCS_MAX_MORPH_TARGETS'];
    const found = defines();
    expect(sorted(found.keys())).toEqual(sorted([...Object.keys(js), ...coreOnly]));
    for (const [name, value] of Object.entries(js)) expect(value, name).toBe(found.get(name));
  });
});

describe('version and unknown codes at run time', () => {
  let gcs: GcsSkin;
  beforeAll(async () => {
    gcs = await initGcsSkin();
  });

  test("the binary's gcs_version() is the header's GCS_VERSION", () => {
    expect(gcs.core.gcs_version()).toBe(defines().get('GCS_VERSION'));
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
  });

  test('the core checks gcs_build_gcs\'s settings itself (C callers have no wrapper), each once', () => {
    const rig = gcs.createRig(makeTube().input);
    const handle = (rig as unknown as { handle: number }).handle;
    const core = gcs.core;
    const refused = (sections: number, criterion: number, width: number) => {
      expect(core.gcs_build_gcs(handle, sections, criterion, width, 1, 0)).toBe(0);
      return { code: core.gcs_last_error_code(), message: (() => { try { gcs.raise(''); } catch (e) { return (e as Error).message; } })() };
    };
    expect(refused(2, 2, 1)).toEqual({ code: 7, message: expect.stringMatching(/between 3 and 256 .*got 2$/) });
    expect(refused(257, 2, 1)).toEqual({ code: 7, message: expect.stringMatching(/got 257$/) });
    expect(refused(6, 3, 1)).toEqual({ code: 1, message: expect.stringMatching(/unknown section criterion 3/) });
    expect(refused(6, 0, 0)).toEqual({ code: 9, message: expect.stringMatching(/influence width must be in \(0, 1\]; got 0/) });
    const ok = core.gcs_build_gcs(handle, 6, 2, 1, 1, 0);
    expect(ok).not.toBe(0);
    core.gcs_deformer_destroy(ok);
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
