// Images sized by their own bytes (web/demo/image-size.ts): each format's header read for its
// dimensions whatever MIME type the file declares; a header cut short or an unknown format is null
// (the page skips what it cannot size).
import { describe, expect, test } from 'vitest';
import { imageSize, imageTooLarge } from '../../web/demo/image-size.js';

const bytes = (length: number, fill: (view: DataView, out: Uint8Array) => void) => {
  const out = new Uint8Array(length);
  fill(new DataView(out.buffer), out);
  return out;
};
const ascii = (s: string) => Array.from(s, (c) => c.charCodeAt(0));

const HEADERS: [string, Uint8Array, { format: string; width: number; height: number; images: number }][] = [
  ['PNG', bytes(33, (v, o) => { o.set([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]); v.setUint32(16, 60000); v.setUint32(20, 3); }), { format: 'PNG', width: 60000, height: 3, images: 1 }],
  ['JPEG', bytes(32, (v, o) => { o.set([0xff, 0xd8, 0xff, 0xe0, 0, 4, 0, 0, 0xff, 0xc2, 0, 11, 8]); v.setUint16(13, 500); v.setUint16(15, 700); }), { format: 'JPEG', width: 700, height: 500, images: 1 }],
  ['GIF', bytes(13, (v, o) => { o.set(ascii('GIF89a')); v.setUint16(6, 20000, true); v.setUint16(8, 30000, true); }), { format: 'GIF', width: 20000, height: 30000, images: 1 }],
  ['BMP', bytes(54, (v, o) => { o.set(ascii('BM')); v.setUint32(14, 40, true); v.setInt32(18, 20000, true); v.setInt32(22, -20000, true); }), { format: 'BMP', width: 20000, height: 20000, images: 1 }],
  ['BMP (core header)', bytes(26, (v, o) => { o.set(ascii('BM')); v.setUint32(14, 12, true); v.setUint16(18, 640, true); v.setUint16(20, 480, true); }), { format: 'BMP', width: 640, height: 480, images: 1 }],
  ['WebP lossy', bytes(30, (v, o) => { o.set(ascii('RIFF')); o.set(ascii('WEBPVP8 '), 8); v.setUint16(26, 16383, true); v.setUint16(28, 100, true); }), { format: 'WebP', width: 16383, height: 100, images: 1 }],
  ['WebP lossless', bytes(25, (v, o) => { o.set(ascii('RIFF')); o.set(ascii('WEBPVP8L'), 8); o[20] = 0x2f; v.setUint32(21, (9999 & 0x3fff) | ((4999 & 0x3fff) << 14), true); }), { format: 'WebP', width: 10000, height: 5000, images: 1 }],
  ['WebP extended', bytes(30, (v, o) => { o.set(ascii('RIFF')); o.set(ascii('WEBPVP8X'), 8); o.set([0x3f, 0x0d, 0x03], 24); o.set([0x1f, 0x4e, 0], 27); }), { format: 'WebP', width: 200000, height: 20000, images: 1 }],
  ['AVIF', bytes(64, (v, o) => { v.setUint32(0, 24); o.set(ascii('ftypavif'), 4); o.set(ascii('ispe'), 40); v.setUint32(48, 50000); v.setUint32(52, 40000); }), { format: 'AVIF', width: 50000, height: 40000, images: 1 }],
  ['KTX2', bytes(80, (v, o) => { o.set([0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a]); v.setUint32(20, 2048, true); v.setUint32(24, 2048, true); v.setUint32(32, 4, true); v.setUint32(36, 6, true); }), { format: 'KTX2', width: 2048, height: 2048, images: 24 }],
];

describe('image formats and sizes from the bytes', () => {
  for (const [name, header, want] of HEADERS) test(name, () => expect(imageSize(header)).toEqual(want));

  test('a header cut short, an unknown format, an ISO-BMFF file that is not AVIF: null', () => {
    expect(imageSize(HEADERS[0][1].subarray(0, 20))).toBeNull();
    expect(imageSize(new TextEncoder().encode('not an image at all'))).toBeNull();
    expect(imageSize(bytes(64, (v, o) => { v.setUint32(0, 24); o.set(ascii('ftypmp42'), 4); o.set(ascii('ispe'), 40); }))).toBeNull();
  });

  test('the budget: a side, then the texels of one image', () => {
    expect(imageTooLarge({ format: 'BMP', width: 20000, height: 20000, images: 1 })).toMatch(/BMP of 20,000 × 20,000 pixels, past the 16,384 a side/);
    expect(imageTooLarge({ format: 'KTX2', width: 2048, height: 2048, images: 24 })).toMatch(/KTX2 of 24 images of 2,048 × 2,048 pixels, past the 67,108,864 texels/);
    expect(imageTooLarge({ format: 'PNG', width: 4096, height: 4096, images: 1 })).toBeNull();
  });
});
