// How the page writes its figures: milliseconds that never read "0.00" (a figure under the last
// digit shown says so), counts with the right plural.

/** "0.06", "12.3", or "< 0.01" for a figure that would round to 0.00; NaN stays "NaN". */
export function msText(ms: number): string {
  if (ms < 0.005) return '< 0.01';
  return ms < 10 ? ms.toFixed(2) : ms.toFixed(1);
}

/** A percentage as msText writes milliseconds ("0.20", "< 0.01"). */
export const percentText = msText;

/** "1 influence", "2 influences", "1,342 sections": `count` (rounded, grouped) and the word in its number. */
export function counted(count: number, singular: string, plural = `${singular}s`): string {
  const n = Math.round(count);
  return `${n.toLocaleString('en')} ${n === 1 ? singular : plural}`;
}
