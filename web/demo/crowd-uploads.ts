// The crowd page's upload meter: bytes sent to the GPU per frame, counted on the calls themselves.
import type { DemoRenderer } from './renderer.js';
import { glContext } from './renderer.js';

/**
 * Bytes uploaded to the GPU, counted on the calls that upload (textures and buffers): WebGL's
 * (WebGLRenderer, or WebGPURenderer's WebGL2 fallback) or, on real WebGPU, the device queue's.
 */
export class UploadCounter {
  bytes = 0;
  constructor(renderer: DemoRenderer) {
    const gl = glContext(renderer);
    if (gl) this.countGl(gl);
    else this.countQueue((renderer as unknown as { backend: { device: { queue: object } } }).backend.device.queue);
  }

  private countQueue(queue: object): void {
    const q = queue as unknown as Record<string, (...a: unknown[]) => unknown>;
    const writeBuffer = q.writeBuffer.bind(queue), writeTexture = q.writeTexture.bind(queue);
    q.writeBuffer = (...a: unknown[]) => {
      const data = a[2] as ArrayBufferView | ArrayBuffer;
      this.bytes += (a[4] as number | undefined) ?? data.byteLength;
      return writeBuffer(...a);
    };
    q.writeTexture = (...a: unknown[]) => {
      const layout = a[2] as { bytesPerRow?: number }, size = a[3] as { height?: number; depthOrArrayLayers?: number } & number[];
      this.bytes += (layout.bytesPerRow ?? 0) * (size.height ?? size[1] ?? 1) * (size.depthOrArrayLayers ?? size[2] ?? 1);
      return writeTexture(...a);
    };
  }

  private countGl(gl: WebGL2RenderingContext): void {
    const channels: Record<number, number> = { [gl.RGBA]: 4, [gl.RGB]: 3, [gl.RG]: 2, [gl.RED]: 1, [gl.RGBA_INTEGER]: 4, [gl.RED_INTEGER]: 1, [gl.LUMINANCE]: 1, [gl.ALPHA]: 1, [gl.LUMINANCE_ALPHA]: 2 };
    const size: Record<number, number> = { [gl.FLOAT]: 4, [gl.HALF_FLOAT]: 2, [gl.UNSIGNED_BYTE]: 1, [gl.BYTE]: 1, [gl.UNSIGNED_SHORT]: 2, [gl.SHORT]: 2, [gl.UNSIGNED_INT]: 4, [gl.INT]: 4 };
    const texel = (format: number, type: number) => (channels[format] ?? 4) * (size[type] ?? 1);
    const g = gl as unknown as Record<string, (...a: unknown[]) => unknown>;
    const wrap = (name: string, count: (a: unknown[]) => number) => {
      const f = g[name].bind(gl);
      g[name] = (...a: unknown[]) => {
        this.bytes += count(a);
        return f(...a);
      };
    };
    const view = (x: unknown) => (ArrayBuffer.isView(x) ? x : null);
    // texSubImage2D(target, level, x, y, w, h, format, type, data…) / (target, level, x, y, format, type, source)
    wrap('texSubImage2D', (a) => (a.length >= 9 ? (a[4] as number) * (a[5] as number) * texel(a[6] as number, a[7] as number)
      : (((a[6] as { width?: number }).width ?? 0) * ((a[6] as { height?: number }).height ?? 0) * texel(a[4] as number, a[5] as number))));
    wrap('texImage2D', (a) => (a.length >= 9 && a[8] ? (a[3] as number) * (a[4] as number) * texel(a[6] as number, a[7] as number) : 0));
    wrap('texSubImage3D', (a) => (a[10] ? (a[5] as number) * (a[6] as number) * (a[7] as number) * texel(a[8] as number, a[9] as number) : 0));
    wrap('bufferSubData', (a) => {
      const v = view(a[2]);
      if (!v) return 0;
      const bpe = (v as unknown as { BYTES_PER_ELEMENT?: number }).BYTES_PER_ELEMENT ?? 1;
      return a[4] ? (a[4] as number) * bpe : v.byteLength - ((a[3] as number) ?? 0) * bpe;
    });
    wrap('bufferData', (a) => view(a[1])?.byteLength ?? 0);
  }
}
