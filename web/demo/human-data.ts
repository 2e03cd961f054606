// The default human's arrays, generated in a module worker (human-worker.ts) so the page keeps
// drawing; on the main thread where module workers are unavailable.
import { createHumanData, type HumanData } from '../lib/human/index.js';

/** Lets the page paint its status before the main thread is busy. */
const nextPaint = () => new Promise<void>((resolve) => setTimeout(resolve, 0));

export function humanDataInWorker(options: { vertices?: number }): Promise<HumanData> {
  return new Promise((resolve, reject) => {
    const onMainThread = async () => {
      await nextPaint();
      try { resolve(createHumanData(options)); } catch (e) { reject(e); }
    };
    let worker: Worker;
    try {
      worker = new Worker(new URL('./human-worker.ts', import.meta.url), { type: 'module' });
    } catch {
      void onMainThread();
      return;
    }
    worker.onmessage = (e: MessageEvent<{ data?: HumanData; error?: string }>) => {
      worker.terminate();
      if (e.data.data) resolve(e.data.data);
      else reject(new Error(`could not generate the human: ${e.data.error}`));
    };
    worker.onerror = (e) => {
      e.preventDefault();
      worker.terminate();
      void onMainThread();
    };
    worker.postMessage(options);
  });
}
