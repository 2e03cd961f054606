// Splitting a GLB into its JSON and BIN chunk and packing them again, for tests that make bad
// files from good ones (tests/cli/gltf-errors.test.ts, tests/cli/hostile.test.ts).
import { writeFileSync } from 'node:fs';

// eslint-disable-next-line @typescript-eslint/no-explicit-any
export type Json = Record<string, any>;

/** The JSON and BIN chunk of a GLB. */
export function splitGlb(bytes: Uint8Array): { json: Json; bin: Uint8Array } {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  const binLength = view.getUint32(20 + jsonLength, true);
  return { json, bin: bytes.slice(28 + jsonLength, 28 + jsonLength + binLength) };
}

/** A GLB of this JSON and BIN chunk (the JSON padded with spaces to 4 bytes). */
export function packGlb(json: Json, bin: Uint8Array): Uint8Array {
  const text = JSON.stringify(json);
  const jsonBytes = new TextEncoder().encode(text + ' '.repeat((4 - (new TextEncoder().encode(text).length % 4)) % 4));
  const out = new Uint8Array(12 + 8 + jsonBytes.length + 8 + bin.length);
  const view = new DataView(out.buffer);
  view.setUint32(0, 0x46546c67, true); // 'glTF'
  view.setUint32(4, 2, true);
  view.setUint32(8, out.length, true);
  view.setUint32(12, jsonBytes.length, true);
  view.setUint32(16, 0x4e4f534a, true); // 'JSON'
  out.set(jsonBytes, 20);
  view.setUint32(20 + jsonBytes.length, bin.length, true);
  view.setUint32(24 + jsonBytes.length, 0x004e4942, true); // 'BIN\0'
  out.set(bin, 28 + jsonBytes.length);
  return out;
}

/** Writes `file`: `source`'s GLB with a copy of its JSON and BIN changed by `edit`; returns the path. */
export function writeGlbVariant(file: string, source: { json: Json; bin: Uint8Array }, edit: (json: Json, bin: DataView) => void): string {
  const json = structuredClone(source.json);
  const bin = source.bin.slice();
  edit(json, new DataView(bin.buffer));
  writeFileSync(file, packGlb(json, bin));
  return file;
}
