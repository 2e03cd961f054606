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

/** Each view's column of the window, left to right (px). */
export function viewRects(): { kind: ViewKind; x: number; width: number }[] {
  const list = views();
  const w = window.innerWidth - sidebarWidth();
  return list.map((kind, i) => {
    const x = Math.round((i * w) / list.length);
    return { kind, x, width: Math.round(((i + 1) * w) / list.length) - x };
  });
}
