// Generates the procedural human off the main thread (about 2 s for 17,023 vertices), so the
// page keeps drawing and shows progress. Returns the raw arrays; three.js objects are made on
// the main thread by humanFromData().
import { createHumanData, type HumanOptions } from '../lib/human/index.js';

self.onmessage = (event: MessageEvent<HumanOptions>) => {
  try {
    const data = createHumanData(event.data);
    const transfer = [data.positions, data.normals, data.uvs, data.indices, data.joints, data.weights, data.weld,
      data.jointPositions, data.inverseBindMatrices].map((a) => a.buffer as ArrayBuffer);
    (self as unknown as Worker).postMessage({ data }, transfer);
  } catch (e) {
    (self as unknown as Worker).postMessage({ error: (e as Error).message ?? String(e) });
  }
};
