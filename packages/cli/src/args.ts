// Command-line values read strictly: a count is decimal digits and nothing else, so '0x3', '1e9',
// ' 7', '+5' and 'NaN' are refused naming the flag, where Number() would take most of them.

/** `text` as a whole number from `min` to `max` for `flag`; throws a RangeError naming the flag. */
export function wholeNumber(flag: string, text: string, min: number, max: number): number {
  const value = /^[0-9]{1,16}$/.test(text) ? Number(text) : NaN;
  if (!(value >= min && value <= max))
    throw new RangeError(`${flag} takes a whole number from ${min} to ${max} in decimal digits; got '${text.length > 40 ? `${text.slice(0, 39)}…` : text}'`);
  return value;
}
