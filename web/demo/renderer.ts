// Which three.js renderer the demo draws with: ?renderer=webgl (default, WebGLRenderer with
// gcs-skin/three and gcs-skin/crowd) or ?renderer=webgpu (three/webgpu's WebGPURenderer with
// gcs-skin/webgpu; real WebGPU where the browser has it, else its WebGL2 fallback). The page says
// which runs; the switch reloads the page with the other one.
import * as THREE from 'three';
import type { WebGPURenderer } from 'three/webgpu';
import type GUI from 'three/addons/libs/lil-gui.module.min.js';

export type RendererKind = 'webgl' | 'webgpu';
export type DemoRenderer = THREE.WebGLRenderer | WebGPURenderer;

export function rendererKind(): RendererKind {
  return new URLSearchParams(location.search).get('renderer') === 'webgpu' ? 'webgpu' : 'webgl';
}

/** The renderer of `kind`, initialised (WebGPURenderer picks its backend in init()). */
export async function createRenderer(kind: RendererKind): Promise<DemoRenderer> {
  if (kind === 'webgpu') {
    const { WebGPURenderer } = await import('three/webgpu');
    const renderer = new WebGPURenderer({ antialias: true });
    await renderer.init();
    return renderer;
  }
  return new THREE.WebGLRenderer({ antialias: true }); // three is in the page's main chunk anyway: no dynamic import
}

/** e.g. "WebGLRenderer", "WebGPURenderer (WebGPU)", "WebGPURenderer (WebGL2 fallback)". */
export function rendererLabel(renderer: DemoRenderer): string {
  const r = renderer as WebGPURenderer;
  if (!r.isWebGPURenderer) return 'WebGLRenderer';
  return (r.backend as { isWebGLBackend?: boolean }).isWebGLBackend ? 'WebGPURenderer (WebGL2 fallback)' : 'WebGPURenderer (WebGPU)';
}

/** The WebGL2 context the renderer draws with, or null (real WebGPU). */
export function glContext(renderer: DemoRenderer): WebGL2RenderingContext | null {
  const r = renderer as WebGPURenderer;
  if (!r.isWebGPURenderer) return (renderer as THREE.WebGLRenderer).getContext() as WebGL2RenderingContext;
  return (r.backend as { gl?: WebGL2RenderingContext }).gl ?? null;
}

/** A GUI switch between the renderers: reloads the page with ?renderer= set. */
export function addRendererSwitch(gui: GUI, kind: RendererKind): void {
  const state = { renderer: kind };
  gui.add(state, 'renderer', { 'WebGLRenderer': 'webgl', 'WebGPURenderer': 'webgpu' }).name('renderer').onChange((value: RendererKind) => {
    const query = new URLSearchParams(location.search);
    if (value === 'webgpu') query.set('renderer', 'webgpu');
    else query.delete('renderer');
    location.search = query.toString();
  });
}
