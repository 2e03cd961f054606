// Checks of a glTF's animations: samplers, channels, key times and values.
import { accessorReader, sparseReader } from './accessors.js';
import { n, plural } from './error.js';
import type { GltfJson } from './json.js';
import { LIMITS } from './limits.js';
import { COMPONENT, isObject, TYPE_COMPONENTS, type Fail, type Ref, type ValidationContext } from './validation-context.js';
import { shownValue } from './shown-name.js';

const INTERPOLATIONS = ['LINEAR', 'STEP', 'CUBICSPLINE'];
const PATH_TYPES: Record<string, string> = { translation: 'VEC3', rotation: 'VEC4', scale: 'VEC3', weights: 'SCALAR' };
const TARGET_PATHS = Object.keys(PATH_TYPES);

/** Animations: samplers, channels, key times and values. */
export function checkAnimations(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { json, buffers, accessors, nodes, animations, named } = ctx;
  /**
   * Key times (accessor `ai`, FLOAT) finite, from 0 on and never decreasing (three's interpolants
   * search them in order: a time going back plays wrong poses silently), where readable.
   */
  const checkTimes = (ai: number, where: string, what: string) => {
    const a = accessors[ai];
    const dense = accessorReader(json, buffers, a), sparse = sparseReader(json, buffers, a);
    const bad = (k: number, t: number, why: string) =>
      fail('BAD_DATA', where, `key ${n(k)} of ${what} (accessor ${ai}) is at time ${+t.toPrecision(6)}: ${why}`);
    if (sparse) for (let k = 0; k < sparse.count; k++) { const t = sparse.value(k, 0); if (!Number.isFinite(t)) bad(sparse.index(k), t, 'key times are finite seconds'); }
    if (!dense || sparse) return; // the order of sparse-patched times is left to the loaders
    let previous = 0;
    for (let k = 0; k < a.count; k++) {
      const t = dense(k, 0);
      if (!Number.isFinite(t)) bad(k, t, 'key times are finite seconds');
      if (t < previous) bad(k, t, k ? `before key ${n(k - 1)} at ${+previous.toPrecision(6)}: key times never go back` : 'key times start at 0 or later');
      previous = t;
    }
  };
  /** Animated values (accessor `ai`) all finite where they are floats and readable. */
  const checkValues = (ai: number, where: string, what: string) => {
    const a = accessors[ai];
    const read = a.componentType === 5126 && !a.sparse ? accessorReader(json, buffers, a) : null;
    if (!read) return;
    const size = TYPE_COMPONENTS[a.type];
    for (let k = 0; k < a.count; k++)
      for (let c = 0; c < size; c++) {
        const v = read(k, c);
        if (!Number.isFinite(v)) fail('BAD_DATA', where, `value ${n(k)} of ${what} (accessor ${ai}) is ${v}: animated values are finite`);
      }
  };

  animations.forEach((a, ai) => {
    const where = `/animations/${ai}`;
    const anim = named('animation', ai, a);
    const ss = Array.isArray(a.samplers) ? a.samplers : fail('BAD_STRUCTURE', `${where}/samplers`, `${anim} has no samplers array`);
    if (!Array.isArray(a.channels)) fail('BAD_STRUCTURE', `${where}/channels`, `${anim} has no channels array`);
    for (const [key, length] of [['samplers', ss.length], ['channels', a.channels.length]] as const)
      if (length > LIMITS.items) fail('TOO_LARGE', `${where}/${key}`, `${anim} has ${n(length)} ${key}, more than the ${n(LIMITS.items)} this loader reads`);
    ss.forEach((s: GltfJson, i: number) => {
      const sw = `${where}/samplers/${i}`;
      if (!isObject(s)) fail('BAD_STRUCTURE', sw, `sampler ${i} of ${anim} is not an object`);
      ref(s.input, accessors, 'accessor', `${sw}/input`, `the input of sampler ${i} of ${anim}`, true);
      ref(s.output, accessors, 'accessor', `${sw}/output`, `the output of sampler ${i} of ${anim}`, true);
      if (s.interpolation !== undefined && !INTERPOLATIONS.includes(s.interpolation))
        fail('BAD_STRUCTURE', `${sw}/interpolation`, `sampler ${i} of ${anim} has interpolation ${shownValue(s.interpolation)}, not ${INTERPOLATIONS.join(', ')}`);
      const input = accessors[s.input];
      if (input.type !== 'SCALAR' || input.componentType !== 5126)
        fail('BAD_STRUCTURE', `${sw}/input`, `the key times of sampler ${i} of ${anim} (accessor ${s.input}) are ${input.type} of ${COMPONENT[input.componentType].name}, not SCALAR of FLOAT`);
      checkTimes(s.input, `${sw}/input`, `sampler ${i} of ${anim}`);
      checkValues(s.output, `${sw}/output`, `sampler ${i} of ${anim}`);
    });
    a.channels.forEach((c: GltfJson, i: number) => {
      if (!isObject(c) || !isObject(c.target)) fail('BAD_STRUCTURE', `${where}/channels/${i}`, `channel ${i} of ${anim} has no target`);
      ref(c.sampler, ss, 'sampler', `${where}/channels/${i}/sampler`, `channel ${i} of ${anim}`, true);
      ref(c.target.node, nodes, 'node', `${where}/channels/${i}/target/node`, `channel ${i} of ${anim}`);
      if (!TARGET_PATHS.includes(c.target.path))
        fail('BAD_STRUCTURE', `${where}/channels/${i}/target/path`,
          `channel ${i} of ${anim} animates ${shownValue(c.target.path) ?? 'nothing'}, not ${TARGET_PATHS.join(', ')}`);
      // The values must be what the path takes, one per key (three per key for CUBICSPLINE: in-tangent,
      // value, out-tangent; weights: one per morph target): three's interpolants read them by stride, and
      // a rotation fed 3-vectors makes its mixer loop forever.
      const sampler = ss[c.sampler], input = accessors[sampler.input], output = accessors[sampler.output];
      const perKey = sampler.interpolation === 'CUBICSPLINE' ? 3 : 1;
      const type = PATH_TYPES[c.target.path as string];
      const sw = `${where}/samplers/${c.sampler}/output`;
      if (output.type !== type)
        fail('BAD_STRUCTURE', sw, `channel ${i} of ${anim} animates ${c.target.path} with ${output.type} values (accessor ${sampler.output}), not ${type}`);
      const keys = input.count * perKey;
      if (c.target.path === 'weights' ? output.count % keys !== 0 : output.count !== keys)
        fail('BAD_STRUCTURE', sw,
          `channel ${i} of ${anim} has ${plural(input.count, 'key')} but ${plural(output.count, 'value')} (accessor ${sampler.output}): ` +
          `${c.target.path === 'weights' ? 'a multiple of ' : ''}${n(keys)} expected${perKey > 1 ? ' (CUBICSPLINE: 3 per key)' : ''}`);
    });
  });
}
