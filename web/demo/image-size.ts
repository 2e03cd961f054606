// The pixel size an image declares in its header (PNG, JPEG, KTX2), read before anything decodes
// it: a few kilobytes can declare a 60,000² texture that the browser or the Basis transcoder would
// then try to allocate. The page refuses such an image (TOO_LARGE) before GLTFLoader sees it.

/** Largest side and texel count (all layers and faces of one image) the page decodes: a 8192² texture at most. */
export const IMAGE_LIMITS = { side: 16_384, texels: 8_192 * 8_192 } as const;

export interface ImageSize {
  format: 'PNG' | 'JPEG' | 'KTX2';
  width: number;
  height: number;
  /** Layers × faces × depth (KTX2); 1 for the others. */
  images: number;
}

const KTX2_ID = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];

/** The size `bytes` declare, or null when its format is none of these (the browser then decodes it with its own limits). */
export function imageSize(bytes: Uint8Array): ImageSize | null {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const has = (sig: number[]) => bytes.length >= sig.length && sig.every((b, i) => bytes[i] === b);
  if (has([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]) && bytes.length >= 24)
    return { format: 'PNG', width: view.getUint32(16), height: view.getUint32(20), images: 1 };
  if (has(KTX2_ID) && bytes.length >= 48) {
    const depth = Math.max(1, view.getUint32(28, true)), layers = Math.max(1, view.getUint32(32, true)), faces = Math.max(1, view.getUint32(36, true));
    return { format: 'KTX2', width: view.getUint32(20, true), height: view.getUint32(24, true), images: depth * layers * faces };
  }
  if (has([0xff, 0xd8])) {
    // JPEG: walk the segments to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC).
    for (let at = 2; at + 9 <= bytes.length;) {
      if (bytes[at] !== 0xff) return null;
      const marker = bytes[at + 1];
      if (marker === 0xff) { at++; continue; }
      if (marker === 0x01 || (marker >= 0xd0 && marker <= 0xd7)) { at += 2; continue; } // no length
      if (marker >= 0xc0 && marker <= 0xcf && marker !== 0xc4 && marker !== 0xc8 && marker !== 0xcc)
        return { format: 'JPEG', width: view.getUint16(at + 7), height: view.getUint16(at + 5), images: 1 };
      at += 2 + view.getUint16(at + 2);
    }
  }
  return null;
}

/** Why an image of this size is refused, or null when the page decodes it. */
export function imageTooLarge(size: ImageSize): string | null {
  const { width, height, images } = size;
  if (width > IMAGE_LIMITS.side || height > IMAGE_LIMITS.side)
    return `is a ${size.format} of ${width.toLocaleString('en-US')} × ${height.toLocaleString('en-US')} pixels, past the ${IMAGE_LIMITS.side.toLocaleString('en-US')} a side this page decodes`;
  if (width * height * images > IMAGE_LIMITS.texels)
    return `is a ${size.format} of ${images.toLocaleString('en-US')} images of ${width.toLocaleString('en-US')} × ${height.toLocaleString('en-US')} pixels, past the ${IMAGE_LIMITS.texels.toLocaleString('en-US')} texels this page decodes`;
  return null;
}
