// The counts a Draco bitstream declares before its geometry: read from its first bytes, without
// decoding, so that a primitive whose Draco data would decode to far more than its glTF accessors
// declare (a few bytes of JSON saying 3 vertices over a million-vertex grid) is refused before the
// decoder allocates or loops over anything. Follows Draco's bitstream (versions 1.x to 2.2):
// header, optional metadata, then the connectivity's counts (sequential or edgebreaker mesh, or a
// point cloud). Browser-safe, no dependency.

/** What a Draco bitstream declares. */
export interface DracoCounts {
  /** 'mesh' (triangles) or 'points' (a point cloud). */
  kind: 'mesh' | 'points';
  /** 'sequential' or 'edgebreaker' (meshes); 'sequential' or 'kd-tree' (point clouds). */
  method: 'sequential' | 'edgebreaker' | 'kd-tree';
  /** Triangles (0 for a point cloud): the decoded index count is 3 × faces. */
  faces: number;
  /**
   * Points: exact for sequential meshes and point clouds; for edgebreaker, the vertices of the
   * connectivity, which attribute seams can split into more points (at most 3 × faces).
   */
  points: number;
  /** Whether `points` is the exact decoded count. */
  exactPoints: boolean;
}

/** Reads the counts of a Draco bitstream; returns a short reason (a string) when the bytes are not one. */
export function readDracoCounts(bytes: Uint8Array): DracoCounts | string {
  const r = new Reader(bytes);
  if (bytes.length < 11 || String.fromCharCode(...bytes.subarray(0, 5)) !== 'DRACO') return 'it does not start with the Draco signature';
  r.at = 5;
  const major = r.u8(), minor = r.u8(), type = r.u8(), method = r.u8(), flags = r.u16();
  const version = major * 256 + minor;
  if (major < 1 || major > 2) return `its Draco version ${major}.${minor} is not one the decoder reads`;
  if (type !== 0 && type !== 1) return `its Draco geometry type ${type} is neither a point cloud nor a mesh`;
  if (flags & 0x8000 && version >= 0x0103 && !skipMetadata(r)) return 'its Draco metadata runs past its data';
  const varint = version >= 0x0200; // counts are varints from 2.0 on (2.2 for sequential meshes)
  if (type === 0) {
    if (method !== 0 && method !== 1) return `its Draco point cloud method ${method} is unknown`;
    const points = r.u32();
    return r.ok ? { kind: 'points', method: method ? 'kd-tree' : 'sequential', faces: 0, points, exactPoints: true } : 'its Draco header is cut short';
  }
  if (method === 0) {
    const wide = version < 0x0202;
    const faces = wide ? r.u32() : r.varint(), points = wide ? r.u32() : r.varint();
    return r.ok ? { kind: 'mesh', method: 'sequential', faces, points, exactPoints: true } : 'its Draco header is cut short';
  }
  if (method !== 1) return `its Draco mesh method ${method} is unknown`;
  r.u8(); // traversal decoder type
  if (version < 0x0202) void (varint ? r.varint() : r.u32()); // new vertices (old streams)
  const points = varint ? r.varint() : r.u32();
  const faces = varint ? r.varint() : r.u32();
  return r.ok ? { kind: 'mesh', method: 'edgebreaker', faces, points, exactPoints: false } : 'its Draco header is cut short';
}

/** Little-endian reads that never throw: past the end, `ok` turns false and reads give 0. */
class Reader {
  at = 0;
  ok = true;
  constructor(private readonly bytes: Uint8Array) {}
  u8(): number {
    if (this.at >= this.bytes.length) { this.ok = false; return 0; }
    return this.bytes[this.at++];
  }
  u16(): number { return this.u8() | (this.u8() << 8); }
  u32(): number { return (this.u16() | (this.u16() << 16)) >>> 0; }
  /** Draco's unsigned LEB128, at most 5 bytes (32 bits). */
  varint(): number {
    let value = 0;
    for (let shift = 0; shift < 35; shift += 7) {
      const b = this.u8();
      value += (b & 0x7f) * 2 ** shift;
      if (!(b & 0x80)) return value > 0xffffffff ? ((this.ok = false), 0) : value;
    }
    this.ok = false;
    return 0;
  }
  skip(n: number): void {
    this.at += n;
    if (this.at > this.bytes.length) this.ok = false;
  }
}

/** Skips Draco's metadata: attribute metadata (an id and an element each), then the file's element. */
function skipMetadata(r: Reader): boolean {
  const attributes = r.varint();
  for (let i = 0; i < attributes && r.ok; i++) {
    r.varint();
    skipElement(r);
  }
  return r.ok && skipElement(r);
}

/**
 * Skips one metadata element: its entries (key and value, a length byte each), then its
 * sub-elements (a key, then an element), iteratively so a crafted nesting cannot overflow the
 * stack; every step reads bytes, so the work is bounded by the data.
 */
function skipElement(r: Reader): boolean {
  const remaining: number[] = []; // sub-elements still to skip, per open element
  for (;;) {
    const entries = r.varint();
    for (let e = 0; e < entries && r.ok; e++) { r.skip(r.u8()); r.skip(r.u8()); }
    remaining.push(r.varint());
    while (remaining.length && remaining[remaining.length - 1] === 0) remaining.pop();
    if (!remaining.length || !r.ok) return r.ok;
    remaining[remaining.length - 1]--;
    r.skip(r.u8()); // the next sub-element's key
  }
}
