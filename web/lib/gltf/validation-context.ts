// What the checks of one glTF file share: the file's top-level collections (each checked to be an
// array of objects, within LIMITS), how a failure is reported, how references and objects are
// named in messages, and what one check learns for the next (each node's parent).
import { GltfError, n, plural, type GltfErrorCode } from './error.js';
import type { BufferData, GltfJson } from './json.js';
import { LIMITS } from './limits.js';

/** Throws the GltfError `code` at `where` with the sentence `${file}: ${what}`. */
export type Fail = (code: GltfErrorCode, where: string, what: string) => never;
/** Checks that `value` at `where` is an index into `array` (named `kind`), if present or required. */
export type Ref = (value: unknown, array: unknown[], kind: string, where: string, owner: string, required?: boolean) => void;

export const isIndex = (x: unknown): x is number => Number.isInteger(x) && (x as number) >= 0;
export const isObject = (x: unknown): x is GltfJson => !!x && typeof x === 'object' && !Array.isArray(x);

export const COMPONENT: Record<number, { name: string; size: number }> = {
  5120: { name: 'BYTE', size: 1 }, 5121: { name: 'UNSIGNED_BYTE', size: 1 }, 5122: { name: 'SHORT', size: 2 },
  5123: { name: 'UNSIGNED_SHORT', size: 2 }, 5125: { name: 'UNSIGNED_INT', size: 4 }, 5126: { name: 'FLOAT', size: 4 },
};
export const TYPE_COMPONENTS: Record<string, number> = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };

/** Bytes of one element; matrix columns start on 4-byte boundaries (glTF 2.0 §3.6.2.4). */
export function elementBytes(type: string, size: number): number {
  if (type === 'MAT2' && size === 1) return 8;
  if (type === 'MAT3' && size === 1) return 12;
  if (type === 'MAT3' && size === 2) return 24;
  return TYPE_COMPONENTS[type] * size;
}

export class ValidationContext {
  readonly accessors: GltfJson[];
  readonly bufferViews: GltfJson[];
  /** The JSON's buffers (`buffers` is their data). */
  readonly bufferDefs: GltfJson[];
  readonly meshes: GltfJson[];
  readonly nodes: GltfJson[];
  readonly skins: GltfJson[];
  readonly scenes: GltfJson[];
  readonly animations: GltfJson[];
  readonly materials: GltfJson[];
  readonly textures: GltfJson[];
  readonly images: GltfJson[];
  readonly samplers: GltfJson[];
  readonly cameras: GltfJson[];
  /** Each node's parent (-1: a root); set by checkNodeGraph. */
  parent: number[] = [];
  /** Where each accessor is used, for messages. */
  private readonly use: string[] = [];

  /** `buffers[i]`: the data of buffer i, or undefined when the buffer has no data to check. */
  constructor(readonly json: GltfJson, readonly file: string, readonly buffers: readonly (BufferData | undefined)[]) {
    this.accessors = this.list('accessors'); this.bufferViews = this.list('bufferViews'); this.bufferDefs = this.list('buffers');
    this.meshes = this.list('meshes'); this.nodes = this.list('nodes'); this.skins = this.list('skins'); this.scenes = this.list('scenes');
    this.animations = this.list('animations'); this.materials = this.list('materials'); this.textures = this.list('textures');
    this.images = this.list('images'); this.samplers = this.list('samplers'); this.cameras = this.list('cameras');
    this.noteUses();
  }

  readonly fail: Fail = (code, where, what) => {
    throw new GltfError(code, this.file, where, `${this.file}: ${what}`);
  };

  readonly ref: Ref = (value, array, kind, where, owner, required = false) => {
    if (value === undefined && !required) return;
    if (!isIndex(value)) this.fail('BAD_STRUCTURE', where, `${owner} refers to ${kind} ${JSON.stringify(value) ?? 'undefined'}, not an index`);
    if (value >= array.length)
      this.fail('BAD_REFERENCE', where, `${owner} refers to ${kind} ${value}, but the file has ${array.length ? `only ${plural(array.length, kind)}` : `no ${kind}`}`);
  };

  /** "mesh 3 'Body'", or "mesh 3" when it has no name. */
  readonly named = (kind: string, i: number, def: GltfJson | undefined): string =>
    typeof def?.name === 'string' && def.name ? `${kind} ${i} '${def.name}'` : `${kind} ${i}`;

  /** "accessor 4 (POSITION of mesh 0 primitive 0)". */
  readonly accessorName = (i: number): string => `accessor ${i}${this.use[i] ? ` (${this.use[i]})` : ''}`;

  readonly nodeName = (i: number): string => this.named('node', i, this.nodes[i]);

  /** The top-level array `name` (empty when absent), each entry an object. */
  private list(name: string): GltfJson[] {
    const a = this.json[name];
    if (a === undefined) return [];
    if (!Array.isArray(a)) this.fail('BAD_STRUCTURE', `/${name}`, `'${name}' is not an array`);
    const limit = name === 'nodes' ? LIMITS.nodes : LIMITS.items;
    if (a.length > limit) this.fail('TOO_LARGE', `/${name}`, `it has ${n(a.length)} ${name}, more than the ${n(limit)} this loader reads`);
    a.forEach((x: unknown, i: number) => { if (!isObject(x)) this.fail('BAD_STRUCTURE', `/${name}/${i}`, `${name}[${i}] is not an object`); });
    return a;
  }

  private noteUses(): void {
    const use = this.use, named = this.named;
    const noteUse = (a: unknown, what: string) => { if (isIndex(a) && use[a] === undefined) use[a] = what; };
    this.meshes.forEach((m, mi) => {
      if (!Array.isArray(m.primitives)) return;
      m.primitives.forEach((p: GltfJson, pi: number) => {
        if (!isObject(p)) return;
        const where = `${named('mesh', mi, m)} primitive ${pi}`;
        if (isObject(p.attributes)) for (const [k, a] of Object.entries(p.attributes)) noteUse(a, `${k} of ${where}`);
        noteUse(p.indices, `indices of ${where}`);
      });
    });
    this.skins.forEach((s, si) => noteUse(s.inverseBindMatrices, `inverse bind matrices of ${named('skin', si, s)}`));
    this.animations.forEach((a, ai) => {
      if (Array.isArray(a.samplers)) a.samplers.forEach((s: GltfJson, i: number) => {
        if (!isObject(s)) return;
        noteUse(s.input, `times of ${named('animation', ai, a)} sampler ${i}`);
        noteUse(s.output, `values of ${named('animation', ai, a)} sampler ${i}`);
      });
    });
  }
}
