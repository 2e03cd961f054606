// The first argument of every adapter's constructor: the GcsSkin that initGcsSkin() gives.
import { asGiven, GcsError } from '../errors.js';
import { GcsSkin } from '../index.js';

/** Throws INVALID_ARGUMENT unless `gcs` is a GcsSkin (`who` names the constructor). */
export function checkGcsSkin(gcs: unknown, who: string): void {
  if (!(gcs instanceof GcsSkin)) throw new GcsError('INVALID_ARGUMENT', `${who} needs the GcsSkin that initGcsSkin() gives; got ${asGiven(gcs)}`);
}
