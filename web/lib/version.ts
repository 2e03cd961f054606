// The version of gcs-skin: this package's, and the core's it expects (gcs_skin.h GCS_VERSION,
// returned by the binary's gcs_version()). tests/lib/boundary.test.ts checks both against
// package.json and the header.

/** gcs-skin's version, as in package.json ('major.minor.patch'). */
export const VERSION = '0.1.0';

/** gcs-skin's version ('major.minor.patch'): the package's, its header's and its core's. */
export function version(): string {
  return VERSION;
}

/** A 'major.minor.patch' version as gcs_skin.h's GCS_VERSION numbers it: major · 10000 + minor · 100 + patch. */
export function versionNumber(v: string): number {
  const [major, minor, patch] = v.split('.').map((x) => parseInt(x, 10));
  return major * 10000 + minor * 100 + patch;
}

/** GCS_VERSION as 'major.minor.patch'. */
export function versionString(n: number): string {
  return `${Math.floor(n / 10000)}.${Math.floor(n / 100) % 100}.${n % 100}`;
}
