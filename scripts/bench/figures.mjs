// The bench's figures the README quotes, written to docs/figures.json by `npm run bench -- --save`
// with the host they were measured on: tests/readme-figures.test.ts fails when the README's quotes
// and this file differ by more than 5 %, so a new run that moves them moves the README too.
import { writeFileSync } from 'node:fs';
import os from 'node:os';

/** The figures kept: the default GCS on the default human (walk, interleaved with a memcpy of its bytes). */
export function quotedFigures(results) {
  const inter = results.comparisons?.interleaved;
  if (!inter) throw new Error('bench --save: no interleaved run (the 17 k walk) in these results');
  const { cpu, cores, node } = results.machine;
  return {
    measured: new Date().toISOString().slice(0, 10),
    host: `${cpu}, ${cores} cores, node ${node}, load average ${os.loadavg()[0].toFixed(1)} at the end`,
    human: { vertices: results.table1.vertices },
    defaultMsPerFrame: inter.defaultMs,
    steppedMsPerFrame: inter.plainMs,
    memcpyMsPerFrame: inter.memcpyMs,
    defaultOverMemcpy: inter.defaultRatio,
  };
}

export function saveFigures(results, file) {
  writeFileSync(file, `${JSON.stringify(quotedFigures(results), null, 2)}\n`);
  console.error(`bench: the README's figures written to ${file}`);
}
