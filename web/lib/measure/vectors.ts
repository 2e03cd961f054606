// Vector helpers the measures share (internal: gcs-skin/measure does not export them).
export function faceNormal(p: ArrayLike<number>, a: number, b: number, c: number, out: Float64Array, o: number): void {
  const ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
  const vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
  out[o] = uy * vz - uz * vy; out[o + 1] = uz * vx - ux * vz; out[o + 2] = ux * vy - uy * vx;
}

export function dist2(p: ArrayLike<number>, a: number, b: number): number {
  const x = p[3 * a] - p[3 * b], y = p[3 * a + 1] - p[3 * b + 1], z = p[3 * a + 2] - p[3 * b + 2];
  return x * x + y * y + z * z;
}

/**
 * The length of (x, y, z). Not Math.hypot: V8's is several times slower, and the probe takes
 * millions a frame; float32 inputs squared in double neither overflow nor underflow.
 */
export function len3(x: number, y: number, z: number): number {
  return Math.sqrt(x * x + y * y + z * z);
}
