// Every public function throws only our errors: every export of every entry of both packages
// (package.json "exports"), every method of the objects they make, called with hostile arguments
// (wrong types, NaN, ±Infinity, huge, negative, fractional, proxies, frozen objects) either returns
// or throws a GcsError / GltfError (the CLI's: ReportError) with a code and our own sentence — never an engine's TypeError
// or RangeError, never engine text inside our message.
import { appendFileSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { beforeAll, describe, expect, test } from 'vitest';
import * as THREE from 'three';
import { GcsError, initGcsSkin, type GcsSkin } from '../../web/lib/index.js';
import { GltfError } from '../../web/lib/gltf/error.js';
import { ReportError } from '../../packages/cli/src/report.js';
import { createHuman, type Human } from '../../web/lib/human/index.js';

const root = fileURLToPath(new URL('../../', import.meta.url));

/** package.json "exports" → the source module of each JavaScript entry. */
function entries(packageDir: string, sourceOf: (dist: string) => string): { name: string; source: string }[] {
  const pkg = JSON.parse(readFileSync(`${root}${packageDir}package.json`, 'utf8')) as { name: string; exports: Record<string, string | { import: string }> };
  return Object.entries(pkg.exports).flatMap(([key, value]) => {
    const dist = typeof value === 'string' ? value : value.import;
    return dist.endsWith('.js') ? [{ name: `${pkg.name}${key.slice(1)}`, source: `${root}${packageDir}${sourceOf(dist)}` }] : [];
  });
}
const ENTRIES = [
  ...entries('', (dist) => dist.replace('./dist/', 'web/lib/').replace(/\.js$/, '.ts')),
  ...entries('packages/cli/', (dist) => dist.replace('./dist/', 'src/').replace(/\.js$/, '.ts')),
];

/**
 * Arguments no function of ours takes. (Not a revoked proxy: every operation on one throws,
 * `instanceof` included, so no check can be made before it.)
 */
const HOSTILE: [string, unknown][] = [
  ['undefined', undefined], ['null', null], ['NaN', NaN], ['Infinity', Infinity], ['-Infinity', -Infinity],
  ['huge', 1e300], ['2^32', 2 ** 32], ['negative', -1], ['fractional', 1.5], ['zero', 0], ['a string', 'x'], ['a number string', '12'],
  ['a bigint', 10n], ['a symbol', Symbol('s')], ['an empty object', {}], ['a frozen object', Object.freeze({ length: 3 })],
  ['an empty array', []], ['an array of NaN', [NaN, NaN, NaN]], ['a function', () => 1],
  ['a proxy that answers every property with NaN', new Proxy({}, { get: () => NaN })],
  ['a non-file URL', new URL('http://example.invalid/a.glb')],
];

/** Engine wording that must never reach a caller, in an error we throw or one that escapes. */
const ENGINE_TEXT = /is not a function|Cannot read propert|Cannot convert|Invalid typed array length|Invalid array length|is not iterable|Maximum call stack|Cannot mix BigInt|revoked|is not a constructor|Cannot create property|Cannot assign to read only|Offset is outside|out of bounds|ERR_[A-Z_]+|undefined is not/;

interface Outcome { call: string; problem: string }

/** Runs `call`, and says what is wrong with how it ended (null: returned, or threw one of ours). */
async function judge(call: string, run: () => unknown): Promise<Outcome | null> {
  if (process.env.HOSTILE_TRACE) appendFileSync(process.env.HOSTILE_TRACE, `${call}\n`);
  try {
    const result = run();
    if (result && typeof (result as Promise<unknown>).then === 'function') await result;
    return null;
  } catch (e) {
    const ours = e instanceof GcsError || e instanceof GltfError || e instanceof ReportError;
    if (!ours) {
      const outcome = { call, problem: `threw ${(e as Error)?.name ?? typeof e}: ${(e as Error)?.message ?? String(e)}` };
      if (process.env.HOSTILE_FAILURES) appendFileSync(process.env.HOSTILE_FAILURES, `${call}\t${outcome.problem.slice(0, 120)}\n`);
      return outcome;
    }
    if (typeof e.code !== 'string' || !e.code) return { call, problem: 'threw ours without a code' };
    if (ENGINE_TEXT.test(e.message)) return { call, problem: `our ${e.code} carries engine text: ${e.message}` };
    return null;
  }
}

/** Argument lists for a function of `arity` parameters: every hostile value in every position (others plausible). */
function argumentLists(arity: number, plausible: unknown[]): [string, unknown[]][] {
  const n = Math.max(1, arity);
  const lists: [string, unknown[]][] = [];
  for (const [label, value] of HOSTILE) {
    lists.push([`all ${label}`, Array(n).fill(value)]);
    for (let i = 0; i < n; i++) {
      const args = plausible.slice(0, n);
      while (args.length < n) args.push(undefined);
      args[i] = value;
      lists.push([`argument ${i} ${label}`, args]);
    }
  }
  return lists;
}

/** Names no hostile call is made to: disposal (checked elsewhere), private methods and @internal raw-pointer ones. */
const SKIPPED = new Set(['constructor', 'dispose', 'raise', 'copyIn', 'viewF32', 'viewU32', 'viewI32', 'refreshViews', 'commit', 'discard', 'prepare',
  'computeSectionsAt', 'computeJointPosesAt', 'computeCompactJointPosesAt', 'gather', 'readString', 'live', 'swappedView', 'perVertex', 'checkRenderer', 'startVelocity',
  'stopVelocity', 'syncAttributes', 'exactBounds', 'run', 'checkCompiled', 'stop', 'show']);
/** Functions that loop for as long as they are asked to (a frame count, a vertex count): called with bounded hostile values only. */
const SLOW = new Set(['timeFrames', 'timeInterleaved', 'createHuman', 'createHumanData', 'humanToGlb']);
/** Classes whose constructor is @internal (made by initGcsSkin, createRig and the builds, exported for instanceof and types). */
const INTERNAL_CONSTRUCTORS = new Set(['GcsSkin', 'Rig', 'Deformer', 'GcsDeformer', 'ClassicDeformer', 'PoseTexels']);
/**
 * Entries whose functions do not check their arguments yet (none: measure, gpu, webgpu and the
 * CLI's report check theirs since web/lib/arguments.ts). Listed by name so that they fail here the
 * day they are fixed (then this list shrinks); everything else must hold now.
 */
const NOT_YET = new Set<string>([]);

let gcs: GcsSkin;
let human: Human;
beforeAll(async () => {
  gcs = await initGcsSkin();
  human = createHuman({ vertices: 2000 });
});

/** The plausible arguments of a public call: a gcs, a skinned mesh, numbers. */
const plausible = () => [gcs, human.mesh, 1, {}];

/** Every method on `object`'s prototype chain (below Object.prototype and three.js's own classes). */
function methodsOf(object: object): string[] {
  const names = new Set<string>();
  for (let p = Object.getPrototypeOf(object); p && p !== Object.prototype && !Object.prototype.hasOwnProperty.call(p, 'isObject3D'); p = Object.getPrototypeOf(p))
    for (const name of Object.getOwnPropertyNames(p)) {
      const d = Object.getOwnPropertyDescriptor(p, name)!;
      if (typeof d.value === 'function' && !SKIPPED.has(name)) names.add(name);
    }
  return [...names];
}

async function walkMethods(label: string, object: object, failures: Outcome[]): Promise<void> {
  for (const name of methodsOf(object)) {
    const f = (object as Record<string, (...a: unknown[]) => unknown>)[name];
    for (const [what, args] of argumentLists(f.length, [1, 1, 1]))
      { const o = await judge(`${label}.${name}(${what})`, () => f.apply(object, args)); if (o) failures.push(o); }
  }
}

describe('every export of every entry, called with hostile arguments', () => {
  for (const entry of ENTRIES) {
    (NOT_YET.has(entry.name) ? test.fails : test)(entry.name, async () => {
      const module = await import(/* @vite-ignore */ entry.source) as Record<string, unknown>;
      const failures: Outcome[] = [];
      for (const [name, value] of Object.entries(module)) {
        if (typeof value !== 'function' || value === GcsError || value === GltfError || INTERNAL_CONSTRUCTORS.has(name)) continue;
        const f = value as ((...a: unknown[]) => unknown) & { prototype?: object };
        const isClass = /^class\b/.test(Function.prototype.toString.call(f));
        const lists = argumentLists(f.length, plausible()).filter(([, args]) => !SLOW.has(name) || args.every((a) => (typeof a !== 'number' || Math.abs(a) < 1e6) && (typeof a !== 'object' || a === null)));
        for (const [what, args] of lists) {
          const o = await judge(`${name}(${what})`, () => (isClass ? Reflect.construct(f, args) : f(...args)));
          if (o) failures.push(o);
        }
      }
      expect(failures.map((f) => `${f.call}: ${f.problem}`).slice(0, 40), `${failures.length} calls ended outside our errors`).toEqual([]);
    }, 300000);
  }

  test('methods of the objects the library makes', async () => {
    const { SkinDeformer } = await import('../../web/lib/three.js');
    const { GcsCrowd, bakeClip } = await import('../../web/lib/crowd.js');
    const failures: Outcome[] = [];
    const rig = gcs.createRig((await import('../../web/lib/three.js')).rigInputFromSkinnedMesh(human.mesh));
    const gcsDeformer = rig.buildGcs();
    const objects: [string, object][] = [
      ['gcs', gcs], ['rig', rig], ['gcsDeformer', gcsDeformer], ['classicDeformer', rig.buildClassic()], ['lbsDeformer', rig.buildLbs()],
      ['skinDeformer', new SkinDeformer(gcs, human.mesh)], ['crowd', new GcsCrowd(gcs, human.mesh, 2)],
      ['bakedClip', bakeClip(human.mesh, human.clips[0] ?? new THREE.AnimationClip('rest', 1, []), 10)],
    ];
    for (const [label, object] of objects) await walkMethods(label, object, failures);
    expect(failures.map((f) => `${f.call}: ${f.problem}`).slice(0, 60), `${failures.length} calls ended outside our errors`).toEqual([]);
  }, 300000);
});
