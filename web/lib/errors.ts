import { GcsErrorNames } from './boundary.generated.js';

/** Error codes of the core (gcs_skin.h GcsError, generated), then those of the JavaScript side. */
export type GcsErrorCode =
  | Exclude<(typeof GcsErrorNames)[number], 'OK'>
  | 'UNKNOWN_CORE_ERROR' // the core reported a code this version of the wrapper does not know (a mismatched binary)
  | 'DISPOSED'
  | 'WASM_LOAD'
  | 'MISSING_PACKAGE'; // JS only: an optional package a function needs is not installed

/** The core's error codes by number (gcs_skin.h GcsError). 0 is GCS_OK, never thrown. */
export const CORE_ERROR_CODES: readonly (GcsErrorCode | null)[] = GcsErrorNames.map((name) => (name === 'OK' ? null : name));

/** Every failure of gcs-skin: a stable `code` and a sentence a user can act on. */
export class GcsError extends Error {
  /** What went wrong, stable across versions: test it instead of the sentence. */
  readonly code: GcsErrorCode;
  constructor(code: GcsErrorCode, message: string) {
    super(message);
    this.name = 'GcsError';
    this.code = code;
  }
  /** Maps a numeric core code (gcs_last_error_code) to its name; 'UNKNOWN_CORE_ERROR' for any other number (GCS_OK included: a failure reported as success). */
  static codeFromNumber(n: number): GcsErrorCode {
    return CORE_ERROR_CODES[n] ?? 'UNKNOWN_CORE_ERROR';
  }
}

/** A value as the caller gave it, for messages: strings in quotes ('6'), so a string is told from a number. */
export function asGiven(value: unknown): string {
  if (typeof value === 'string') return `'${value}'`;
  if (typeof value === 'bigint') return `${value}n`;
  if (typeof value === 'symbol') return 'a symbol';
  if (typeof value === 'function') return 'a function';
  if (Array.isArray(value)) return 'an array';
  if (value !== null && typeof value === 'object') return 'an object';
  return String(value);
}
