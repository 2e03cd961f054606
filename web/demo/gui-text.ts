// lil-gui writes option labels, and the selected option's display, with innerHTML: a label that
// comes from a file or a URL (a clip name, a dropped file's name, ?clip=) would be markup there,
// and an <img onerror> in it runs. These helpers give lil-gui such labels HTML-escaped, so the page
// shows them as they are and runs nothing.

/** Text made safe to place in HTML: & < > " ' as entities. */
export const escapeHtml = (s: string) =>
  s.replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]!);

/**
 * A lil-gui options map (label → value) whose labels are escaped, the values unchanged: a list of
 * strings is its own labels. The controller's value must be one of the values (lil-gui shows a
 * value it does not list as HTML).
 */
export function textOptions(options: Readonly<Record<string, string>> | readonly string[]): Record<string, string> {
  const entries = Array.isArray(options) ? options.map((v) => [v, v] as const) : Object.entries(options);
  return Object.fromEntries(entries.map(([label, value]) => [escapeHtml(label), value]));
}
