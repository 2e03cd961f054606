import { checkFinite, checkNumbers } from '../arguments.js';
// Statistics of the measures: median, percentiles (quickselect, no full sort) and the largest value.
/**
 * The median (the 50th percentile, nearest rank); NaN for no values.
 * @param values The numbers (not changed).
 * @returns Their median.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function median(values: ArrayLike<number>): number {
  checkNumbers(values, 'values', 'median');
  return percentile(values, 50);
}

/**
 * The p-th percentile (0..100, nearest rank on the sorted values, NaN sorting last); NaN for no
 * values. By selection, not a sort: the fidelity probe takes it over a million distances.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function percentile(values: ArrayLike<number>, p: number): number {
  checkNumbers(values, 'values', 'percentile');
  checkFinite(p, 'p', 'percentile');
  const n = values.length;
  if (!n) return NaN;
  const rank = Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1));
  const a = new Float64Array(n);
  let m = 0;
  for (let i = 0; i < n; i++) if (!Number.isNaN(values[i])) a[m++] = values[i];
  return rank < m ? select(a, m, rank) : NaN;
}

/** The k-th smallest of a[0 … n−1] (no NaN), partly reordering a (Hoare's quickselect, median-of-three pivots). */
function select(a: Float64Array, n: number, k: number): number {
  let lo = 0, hi = n - 1;
  while (hi > lo) {
    const mid = (lo + hi) >> 1;
    const x = a[lo], y = a[mid], z = a[hi];
    const pivot = x < y ? (y < z ? y : x < z ? z : x) : (x < z ? x : y < z ? z : y);
    let i = lo, j = hi;
    while (i <= j) {
      while (a[i] < pivot) i++;
      while (a[j] > pivot) j--;
      if (i <= j) { const t = a[i]; a[i] = a[j]; a[j] = t; i++; j--; }
    }
    if (k <= j) hi = j;
    else if (k >= i) lo = i;
    else return a[k];
  }
  return a[k];
}

/**
 * The largest value (NaN counts as +∞); NaN for an empty array.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (numbers that are not an array or a typed array, a record that is not an object, a missing method, a number that is not finite).
 */
export function maxOf(a: ArrayLike<number>): number {
  checkNumbers(a, 'values', 'maxOf');
  let m = -Infinity;
  for (let i = 0; i < a.length; i++) if (!(a[i] <= m)) m = Number.isNaN(a[i]) ? Infinity : a[i];
  return a.length ? m : NaN;
}
