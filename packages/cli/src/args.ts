// Command-line arguments walked one at a time, and values read strictly: a count is decimal digits
// and nothing else, so '0x3', '1e9', ' 7', '+5' and 'NaN' are refused naming the flag, where
// Number() would take most of them.

/**
 * Calls `each` with every argument of `argv` in turn; its `value()` takes the next argument as the
 * current flag's value (throwing `refuse('<flag> needs a value')` when there is none). `each`
 * returning true stops the walk.
 */
export function walkArguments(argv: string[], refuse: (message: string) => Error, each: (arg: string, value: () => string) => boolean | void): void {
  for (let i = 0; i < argv.length; i++) {
    const flag = argv[i];
    const value = () => {
      const v = argv[++i];
      if (v === undefined) throw refuse(`${flag} needs a value`);
      return v;
    };
    if (each(flag, value) === true) return;
  }
}

/** `text` as a whole number from `min` to `max` for `flag`; throws a RangeError naming the flag. */
export function wholeNumber(flag: string, text: string, min: number, max: number): number {
  const value = /^[0-9]{1,16}$/.test(text) ? Number(text) : NaN;
  if (!(value >= min && value <= max))
    throw new RangeError(`${flag} takes a whole number from ${min} to ${max} in decimal digits; got '${text.length > 40 ? `${text.slice(0, 39)}…` : text}'`);
  return value;
}
