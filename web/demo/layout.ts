// Where things go on the page: the control column on the right (opaque; the GUI overlays the
// picture on narrow windows instead), and the views side by side in the rest.
import { params, type ViewKind } from './state.js';

/** Width of the control column on the right (0: the GUI overlays the views on narrow windows). */
export function sidebarWidth(): number {
  return window.innerWidth >= 900 ? 290 : 0;
}

/** Sizes the control column for the window; returns the width left for the picture. */
export function applySidebar(): number {
  const side = sidebarWidth();
  document.documentElement.style.setProperty('--sidebar', `${side}px`);
  const sidebar = document.getElementById('sidebar');
  if (sidebar) sidebar.hidden = side === 0;
  return window.innerWidth - side;
}

export function views(): ViewKind[] {
  return params.lbsView ? ['gcs', 'classic', 'lbs'] : ['gcs', 'classic'];
}

export interface ViewRect { kind: ViewKind; x: number; width: number }
let rects: ViewRect[] = [];
let rectsFor = { width: -1, lbs: false };

/** Each view's column of the window, left to right (px); the same array until the window or the views change (render() asks every frame). */
export function viewRects(): readonly ViewRect[] {
  const w = window.innerWidth - sidebarWidth();
  if (rectsFor.width !== w || rectsFor.lbs !== params.lbsView) {
    const list = views();
    rects = list.map((kind, i) => {
      const x = Math.round((i * w) / list.length);
      return { kind, x, width: Math.round(((i + 1) * w) / list.length) - x };
    });
    rectsFor = { width: w, lbs: params.lbsView };
  }
  return rects;
}
