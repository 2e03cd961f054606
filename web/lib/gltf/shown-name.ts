// A name or URI from a file, as our messages show it: at most 48 characters (a 1 MB node name
// must not make a 1 MB error line; with a path and a sentence, a line stays within ~200) and with control characters and bidirectional overrides
// written as escapes (\x1b, \n, \u202e), so neither a terminal nor the page is steered by them.
// Browser-safe.

/** Characters shown of a name before it is cut (with "…"). */
export const SHOWN_NAME_LENGTH = 48;

/** Control characters (C0, DEL, C1), line and paragraph separators, bidirectional overrides and isolates. */
const UNPRINTABLE = /[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]/g;

/** `s` with its unprintable characters written as escapes. */
export function printable(s: string): string {
  return s.replace(UNPRINTABLE, (c) => {
    const code = c.charCodeAt(0);
    if (c === '\n') return '\\n';
    if (c === '\r') return '\\r';
    if (c === '\t') return '\\t';
    return code < 0x100 ? `\\x${code.toString(16).padStart(2, '0')}` : `\\u${code.toString(16).padStart(4, '0')}`;
  });
}

/** A file's name or URI for a message: cut to `max` characters with "…", then escaped. */
export function shownName(s: string, max = SHOWN_NAME_LENGTH): string {
  const chars = Array.from(s.slice(0, 2 * max + 2)); // whole code points: a cut never splits a surrogate pair
  return printable(chars.length > max ? `${chars.slice(0, max - 1).join('')}…` : s);
}

/** A value from a file as JSON for a message, cut and escaped like a name (undefined stays undefined). */
export function shownValue(value: unknown): string | undefined {
  const text = JSON.stringify(value);
  return text === undefined ? undefined : shownName(text);
}
