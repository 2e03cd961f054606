// Loads the shared test characters (../shared/models, never copied into the repo) in node.
// The loading itself lives in the library (packages/cli/src/gltf-node.ts, used by `gcs-skin report`).
import { existsSync, readdirSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

export { loadGltfFile as loadGlb, skinMatricesAt, type LoadedModel } from '../../packages/cli/src/gltf-node.js';

export const MODELS_DIR = resolve(dirname(fileURLToPath(import.meta.url)), '../../../shared/models');

/** The .glb files of ../shared/models, or a reason why there are none. */
export function sharedModels(): { files: string[]; reason?: string } {
  if (!existsSync(MODELS_DIR)) return { files: [], reason: `skipped: ${MODELS_DIR} is absent (the shared test models are not on this machine)` };
  const files = readdirSync(MODELS_DIR).filter((f) => f.endsWith('.glb')).sort().map((f) => join(MODELS_DIR, f));
  return files.length ? { files } : { files, reason: `skipped: no .glb in ${MODELS_DIR}` };
}
