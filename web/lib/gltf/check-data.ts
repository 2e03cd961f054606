// Checks of a glTF's data: buffers, buffer views, accessors (sparse parts included) each inside the
// one below, and the bytes the loaders would allocate against the bytes the file has.
import { sparseReader } from './accessors.js';
import { GltfError, n, plural } from './error.js';
import { LIMITS } from './limits.js';
import { COMPONENT, elementBytes, isIndex, isObject, TYPE_COMPONENTS, type Fail, type Ref, type ValidationContext } from './validation-context.js';
import { shownValue } from './shown-name.js';

/** Buffers: declared byteLength against the data. */
export function checkBuffers(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const { file, buffers, bufferDefs } = ctx;
  bufferDefs.forEach((b, i) => {
    const where = `/buffers/${i}`;
    if (!isIndex(b.byteLength)) fail('BAD_STRUCTURE', `${where}/byteLength`, `buffer ${i}'s byteLength is ${shownValue(b.byteLength)}, not a whole number`);
    const data = buffers[i];
    if (data && b.byteLength > data.byteLength)
      throw new GltfError('TRUNCATED', file, where,
        `${file} is truncated: buffer ${i} says ${n(b.byteLength)} bytes but ${data.source} has ${n(data.byteLength)}`);
  });
}

/** Buffer views inside their buffers (and meshopt-compressed data inside theirs). */
export function checkBufferViews(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { buffers, bufferViews, bufferDefs } = ctx;
  bufferViews.forEach((v, i) => {
    const where = `/bufferViews/${i}`;
    ref(v.buffer, bufferDefs, 'buffer', `${where}/buffer`, `buffer view ${i}`, true);
    const offset = v.byteOffset ?? 0;
    if (!isIndex(offset)) fail('BAD_STRUCTURE', `${where}/byteOffset`, `buffer view ${i}'s byteOffset is ${shownValue(offset)}, not a whole number`);
    if (!isIndex(v.byteLength) || v.byteLength < 1)
      fail('BAD_STRUCTURE', `${where}/byteLength`, `buffer view ${i}'s byteLength is ${shownValue(v.byteLength)}, not a whole number ≥ 1`);
    if (v.byteStride !== undefined && (!Number.isInteger(v.byteStride) || v.byteStride < 4 || v.byteStride > 252))
      fail('BAD_STRUCTURE', `${where}/byteStride`, `buffer view ${i}'s byteStride is ${shownValue(v.byteStride)}, not a whole number from 4 to 252`);
    const meshopt = v.extensions?.EXT_meshopt_compression;
    if (meshopt !== undefined) {
      // The compressed bytes: inside their buffer; decoded, count × byteStride bytes, inside this view.
      const mw = `${where}/extensions/EXT_meshopt_compression`;
      if (!isObject(meshopt)) fail('BAD_STRUCTURE', mw, `the EXT_meshopt_compression of buffer view ${i} is not an object`);
      ref(meshopt.buffer, bufferDefs, 'buffer', `${mw}/buffer`, `the compressed data of buffer view ${i}`, true);
      const mo = meshopt.byteOffset ?? 0;
      for (const [key, value] of [['byteOffset', mo], ['byteLength', meshopt.byteLength], ['byteStride', meshopt.byteStride], ['count', meshopt.count]] as const)
        if (!isIndex(value)) fail('BAD_STRUCTURE', `${mw}/${key}`, `the compressed data of buffer view ${i} has ${key} ${shownValue(value)}, not a whole number`);
      const data = buffers[meshopt.buffer];
      const have = data ? Math.min(data.byteLength, bufferDefs[meshopt.buffer].byteLength) : bufferDefs[meshopt.buffer].byteLength;
      if (mo + meshopt.byteLength > have)
        fail('OUT_OF_BOUNDS', mw,
          `the compressed data of buffer view ${i} (bytes ${n(mo)} to ${n(mo + meshopt.byteLength)} of buffer ${meshopt.buffer}) goes past the end of its buffer, which has ${n(have)} bytes`);
      if (meshopt.count * meshopt.byteStride > v.byteLength)
        fail('OUT_OF_BOUNDS', mw,
          `buffer view ${i} decompresses to ${plural(meshopt.count, 'element')} of ${n(meshopt.byteStride)} bytes, more than its byteLength ${n(v.byteLength)}`);
    }
    const size = bufferDefs[v.buffer].byteLength;
    if (offset + v.byteLength > size)
      fail('OUT_OF_BOUNDS', where,
        `buffer view ${i} (bytes ${n(offset)} to ${n(offset + v.byteLength)} of buffer ${v.buffer}) goes past the end of its buffer, which has ${n(size)} bytes`);
  });
}

/** Accessors (and their sparse parts) inside their buffer views. */
export function checkAccessors(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const ref: Ref = ctx.ref;
  const { accessors, bufferViews, accessorName } = ctx;
  /** Checks that `count` elements of `bytes` each, `stride` apart from `offset`, fit in buffer view `bv`. */
  const fits = (where: string, what: string, bv: number, offset: number, count: number, bytes: number, stride: number) => {
    const need = offset + stride * (count - 1) + bytes;
    const have = bufferViews[bv].byteLength;
    if (need > have)
      fail('OUT_OF_BOUNDS', where,
        `${what} has count ${n(count)}, too many for buffer view ${bv}: ${plural(count, 'element')} of ${n(bytes)} bytes` +
        `${stride !== bytes ? `, ${n(stride)} apart,` : ''} from byte ${n(offset)} need ${n(need)} bytes but the view has ${n(have)}`);
  };
  accessors.forEach((a, i) => {
    const where = `/accessors/${i}`;
    const name = accessorName(i);
    const component = COMPONENT[a.componentType];
    if (!component) fail('BAD_STRUCTURE', `${where}/componentType`, `${name} has componentType ${shownValue(a.componentType)}, not a glTF component type`);
    if (!(a.type in TYPE_COMPONENTS)) fail('BAD_STRUCTURE', `${where}/type`, `${name} has type ${shownValue(a.type)}, not SCALAR, VEC2-4 or MAT2-4`);
    if (!isIndex(a.count) || a.count < 1) fail('BAD_STRUCTURE', `${where}/count`, `${name} has count ${shownValue(a.count)}, not a whole number ≥ 1`);
    const offset = a.byteOffset ?? 0;
    if (!isIndex(offset)) fail('BAD_STRUCTURE', `${where}/byteOffset`, `${name} has byteOffset ${shownValue(offset)}, not a whole number`);
    const bytes = elementBytes(a.type, component.size);
    if (a.bufferView !== undefined) {
      ref(a.bufferView, bufferViews, 'buffer view', `${where}/bufferView`, name);
      const stride = bufferViews[a.bufferView].byteStride ?? bytes;
      if (stride < bytes)
        fail('BAD_STRUCTURE', where, `${name} has ${n(bytes)}-byte elements but buffer view ${a.bufferView}'s byteStride is ${stride}`);
      fits(where, name, a.bufferView, offset, a.count, bytes, stride);
    } else if (offset !== 0) {
      fail('BAD_STRUCTURE', `${where}/byteOffset`, `${name} has a byteOffset but no buffer view`);
    }
    if (a.sparse !== undefined) {
      const s = a.sparse;
      const sw = `${where}/sparse`;
      if (!isObject(s) || !isObject(s.indices) || !isObject(s.values)) fail('BAD_STRUCTURE', sw, `the sparse part of ${name} lacks indices or values`);
      if (!isIndex(s.count) || s.count < 1 || s.count > a.count)
        fail('BAD_STRUCTURE', `${sw}/count`, `the sparse count of ${name} is ${shownValue(s.count)}, not from 1 to its count ${n(a.count)}`);
      const ic = COMPONENT[s.indices.componentType];
      if (![5121, 5123, 5125].includes(s.indices.componentType))
        fail('BAD_STRUCTURE', `${sw}/indices/componentType`, `the sparse indices of ${name} have componentType ${shownValue(s.indices.componentType)}, not an unsigned integer type`);
      for (const [part, size] of [['indices', ic.size], ['values', bytes]] as const) {
        const p = s[part];
        ref(p.bufferView, bufferViews, 'buffer view', `${sw}/${part}/bufferView`, `the sparse ${part} of ${name}`, true);
        const po = p.byteOffset ?? 0;
        if (!isIndex(po)) fail('BAD_STRUCTURE', `${sw}/${part}/byteOffset`, `the sparse ${part} of ${name} have byteOffset ${shownValue(po)}, not a whole number`);
        fits(`${sw}/${part}`, `the sparse ${part} of ${name}`, p.bufferView, po, s.count, size, size);
      }
    }
  });
}

/** What the loaders will allocate against the data the file has. */
export function checkDeclaredBytes(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const { file, buffers, accessors, bufferViews, bufferDefs, accessorName } = ctx;
  // What the loaders will allocate (accessors, sparse parts, meshopt-decoded views), against the data the file has.
  let present = 0;
  bufferDefs.forEach((b, i) => { if (buffers[i]) present += Math.min(b.byteLength, buffers[i]!.byteLength); });
  let expanded = 0, largest = -1, largestBytes = 0;
  accessors.forEach((a, i) => {
    const size = elementBytes(a.type, COMPONENT[a.componentType].size);
    const bytes = a.count * size + (a.sparse ? a.sparse.count * (size + COMPONENT[a.sparse.indices.componentType].size) : 0);
    expanded += bytes;
    if (bytes > largestBytes) { largest = i; largestBytes = bytes; }
  });
  for (const v of bufferViews) if (v.extensions?.EXT_meshopt_compression) expanded += v.byteLength;
  const allowed = LIMITS.expandedFloor + LIMITS.expansion * present;
  if (expanded > allowed)
    fail('TOO_LARGE', largest >= 0 ? `/accessors/${largest}` : '/bufferViews',
      `accessors declare ${n(expanded)} bytes${largest >= 0 ? ` (accessor ${largest}: ${plural(accessors[largest].count, 'element')})` : ''}` +
      ` from ${n(present)} bytes of data, past ${LIMITS.expandedFloor / 2 ** 20} MiB + ${LIMITS.expansion}× that`);
}

/** Sparse indices read from the data. */
export function checkSparseIndices(ctx: ValidationContext): void {
  const fail: Fail = ctx.fail;
  const { json, buffers, accessors, accessorName } = ctx;
  // Sparse indices: below the accessor's count and increasing (else the loaders write past their arrays or skip values).
  accessors.forEach((a, i) => {
    const sparse = sparseReader(json, buffers, a);
    if (!sparse) return;
    for (let k = 0, previous = -1; k < sparse.count; k++) {
      const index = sparse.index(k);
      if (index >= a.count)
        fail('BAD_DATA', `/accessors/${i}/sparse/indices`, `sparse index ${k} of ${accessorName(i)} is ${n(index)}, past its count ${n(a.count)}`);
      if (index <= previous)
        fail('BAD_DATA', `/accessors/${i}/sparse/indices`, `the sparse indices of ${accessorName(i)} do not increase: index ${k} is ${n(index)} after ${n(previous)}`);
      previous = index;
    }
  });
}
