/** Error codes of the core (gcs_skin.h GcsError), as strings. */
export type GcsErrorCode =
  | 'INVALID_ARGUMENT'
  | 'LENGTH_MISMATCH'
  | 'INDEX_OUT_OF_RANGE'
  | 'JOINT_OUT_OF_RANGE'
  | 'NON_FINITE'
  | 'BAD_WEIGHTS'
  | 'SECTION_COUNT'
  | 'ZERO_LENGTH_BONE'
  | 'OUT_OF_RANGE'
  | 'NO_SKIN'
  | 'OUT_OF_MEMORY'
  | 'DEGENERATE'
  | 'DISPOSED'
  | 'WASM_LOAD'
  | 'MISSING_PACKAGE'; // JS only: an optional package a function needs is not installed

const CODES: GcsErrorCode[] = [
  'INVALID_ARGUMENT', // 0 is OK: never thrown; index 0 stands in for an unknown code
  'INVALID_ARGUMENT',
  'LENGTH_MISMATCH',
  'INDEX_OUT_OF_RANGE',
  'JOINT_OUT_OF_RANGE',
  'NON_FINITE',
  'BAD_WEIGHTS',
  'SECTION_COUNT',
  'ZERO_LENGTH_BONE',
  'OUT_OF_RANGE',
  'NO_SKIN',
  'OUT_OF_MEMORY',
  'DEGENERATE',
];

/** Every failure of gcs-skin: a stable `code` and a sentence a user can act on. */
export class GcsError extends Error {
  readonly code: GcsErrorCode;
  constructor(code: GcsErrorCode, message: string) {
    super(message);
    this.name = 'GcsError';
    this.code = code;
  }
  /** Maps a numeric core code (gcs_last_error_code) to its name. */
  static codeFromNumber(n: number): GcsErrorCode {
    return CODES[n] ?? 'INVALID_ARGUMENT';
  }
}
