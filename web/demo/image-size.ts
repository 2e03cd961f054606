// The format and pixel size of an image, read from its own bytes before anything decodes it (the
// MIME type a file declares is not trusted: a 66-byte RLE BMP labelled image/png can declare
// 20,000² pixels). A few kilobytes can declare a texture that the browser or the Basis transcoder
// would then try to allocate; the page skips such an image (the character is drawn untextured, with
// a note) before GLTFLoader sees it.

/** Largest side, texels of one image (all layers and faces) and texels of all a file's images together, that the page decodes. */
export const IMAGE_LIMITS = { side: 16_384, texels: 8_192 * 8_192, totalTexels: 4 * 8_192 * 8_192 } as const;

export type ImageFormat = 'PNG' | 'JPEG' | 'GIF' | 'BMP' | 'WebP' | 'AVIF' | 'KTX2';

/** The formats the page reads, as a note lists them. */
export const IMAGE_FORMATS = 'PNG, JPEG, GIF, BMP, WebP, AVIF, KTX2';

export interface ImageSize {
  format: ImageFormat;
  width: number;
  height: number;
  /** Layers × faces × depth (KTX2); 1 for the others. */
  images: number;
}

const KTX2_ID = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const ascii = (s: string) => Array.from(s, (c) => c.charCodeAt(0));

/**
 * The format and size `bytes` declare, from their signature and header alone; null when they are
 * none of IMAGE_FORMATS or their header is cut short (the page does not decode what it cannot size).
 */
export function imageSize(bytes: Uint8Array): ImageSize | null {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const has = (sig: number[], at = 0) => bytes.length >= at + sig.length && sig.every((b, i) => bytes[at + i] === b);
  const size = (format: ImageFormat, width: number, height: number, images = 1): ImageSize => ({ format, width, height, images });
  if (has([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]))
    return bytes.length >= 24 ? size('PNG', view.getUint32(16), view.getUint32(20)) : null;
  if (has(KTX2_ID)) {
    if (bytes.length < 48) return null;
    const depth = Math.max(1, view.getUint32(28, true)), layers = Math.max(1, view.getUint32(32, true)), faces = Math.max(1, view.getUint32(36, true));
    return size('KTX2', view.getUint32(20, true), view.getUint32(24, true), depth * layers * faces);
  }
  if (has([0xff, 0xd8])) return jpegSize(bytes, view);
  if (has(ascii('GIF87a')) || has(ascii('GIF89a')))
    return bytes.length >= 10 ? size('GIF', view.getUint16(6, true), view.getUint16(8, true)) : null;
  if (has(ascii('BM'))) {
    if (bytes.length < 26) return null;
    // BITMAPCOREHEADER (12 bytes): 16-bit sides; every later header: signed 32-bit (negative height: top-down).
    if (view.getUint32(14, true) === 12) return size('BMP', view.getUint16(18, true), view.getUint16(20, true));
    return size('BMP', Math.abs(view.getInt32(18, true)), Math.abs(view.getInt32(22, true)));
  }
  if (has(ascii('RIFF')) && has(ascii('WEBP'), 8)) return webpSize(bytes, view);
  if (has(ascii('ftyp'), 4)) return avifSize(bytes, view);
  return null;
}

/** JPEG: walk the segments to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC). */
function jpegSize(bytes: Uint8Array, view: DataView): ImageSize | null {
  for (let at = 2; at + 9 <= bytes.length;) {
    if (bytes[at] !== 0xff) return null;
    const marker = bytes[at + 1];
    if (marker === 0xff) { at++; continue; }
    if (marker === 0x01 || (marker >= 0xd0 && marker <= 0xd7)) { at += 2; continue; } // no length
    if (marker >= 0xc0 && marker <= 0xcf && marker !== 0xc4 && marker !== 0xc8 && marker !== 0xcc)
      return { format: 'JPEG', width: view.getUint16(at + 7), height: view.getUint16(at + 5), images: 1 };
    at += 2 + view.getUint16(at + 2);
  }
  return null;
}

/** WebP: the first chunk, lossy (VP8), lossless (VP8L) or extended (VP8X: the canvas). */
function webpSize(bytes: Uint8Array, view: DataView): ImageSize | null {
  const chunk = String.fromCharCode(...bytes.subarray(12, 16));
  if (chunk === 'VP8 ' && bytes.length >= 30)
    return { format: 'WebP', width: view.getUint16(26, true) & 0x3fff, height: view.getUint16(28, true) & 0x3fff, images: 1 };
  if (chunk === 'VP8L' && bytes.length >= 25) {
    const bits = view.getUint32(21, true);
    return { format: 'WebP', width: (bits & 0x3fff) + 1, height: ((bits >>> 14) & 0x3fff) + 1, images: 1 };
  }
  if (chunk === 'VP8X' && bytes.length >= 30) {
    const u24 = (at: number) => bytes[at] | (bytes[at + 1] << 8) | (bytes[at + 2] << 16);
    return { format: 'WebP', width: u24(24) + 1, height: u24(27) + 1, images: 1 };
  }
  return null;
}

/**
 * AVIF (an ISO-BMFF file of brand avif or avis): the largest image spatial extent ('ispe') its
 * header declares (a grid's tiles and the grid itself each have one); null without any.
 */
function avifSize(bytes: Uint8Array, view: DataView): ImageSize | null {
  const boxEnd = Math.min(bytes.length, view.getUint32(0), 64);
  const brands = String.fromCharCode(...bytes.subarray(8, Math.max(8, boxEnd)));
  if (!/avi[fs]/.test(brands)) return null;
  let width = 0, height = 0, found = false;
  const end = Math.min(bytes.length, 1 << 20) - 16;
  for (let at = 4; at <= end; at++) {
    if (bytes[at] !== 0x69 || bytes[at + 1] !== 0x73 || bytes[at + 2] !== 0x70 || bytes[at + 3] !== 0x65) continue; // 'ispe'
    found = true;
    width = Math.max(width, view.getUint32(at + 8));
    height = Math.max(height, view.getUint32(at + 12));
  }
  return found ? { format: 'AVIF', width, height, images: 1 } : null;
}

/** Texels an image of this size decodes to. */
export const texelsOf = (size: ImageSize): number => size.width * size.height * size.images;

/** Why an image of this size is not decoded, or null when the page decodes it. */
export function imageTooLarge(size: ImageSize): string | null {
  const { width, height, images } = size;
  if (width > IMAGE_LIMITS.side || height > IMAGE_LIMITS.side)
    return `is a ${size.format} of ${width.toLocaleString('en-US')} × ${height.toLocaleString('en-US')} pixels, past the ${IMAGE_LIMITS.side.toLocaleString('en-US')} a side this page decodes`;
  if (texelsOf(size) > IMAGE_LIMITS.texels)
    return `is a ${size.format} of ${images > 1 ? `${images.toLocaleString('en-US')} images of ` : ''}${width.toLocaleString('en-US')} × ${height.toLocaleString('en-US')} pixels, past the ${IMAGE_LIMITS.texels.toLocaleString('en-US')} texels this page decodes`;
  return null;
}

/** The MIME type of a sniffed format (the blob GLTFLoader reads is labelled by its bytes, not the file's word). */
export const MIME_TYPES: Record<ImageFormat, string> = {
  PNG: 'image/png', JPEG: 'image/jpeg', GIF: 'image/gif', BMP: 'image/bmp', WebP: 'image/webp', AVIF: 'image/avif', KTX2: 'image/ktx2',
};
