#!/usr/bin/env node
// gcs-skin command line (the package @gcs-skin/cli): a table of subcommands, each a module of
// ../src (built into ../dist by `npm run build:lib`, with the part of the core it imports) exporting
// `run(argv) → Promise<exit code>` and `usage`. The library's own bin (gcs-skin/bin/gcs-skin.mjs)
// runs this file.
const SUBCOMMANDS = {
  human: { module: '../dist/human.js', about: 'write the default human character (mesh, skin, clips) as .glb' },
  report: { module: '../dist/report.js', about: 'build every deformer on a glTF skinned model and report counts, timings, fidelity' },
};

function usage() {
  const w = Math.max(...Object.keys(SUBCOMMANDS).map((k) => k.length));
  return ['usage: gcs-skin <command> [options]', 'commands:',
    ...Object.entries(SUBCOMMANDS).map(([k, v]) => `  ${k.padEnd(w)}  ${v.about}`),
    "run 'gcs-skin <command> --help' for a command's options"].join('\n');
}

const [cmd, ...rest] = process.argv.slice(2);
if (cmd === '-h' || cmd === '--help') {
  console.log(usage());
} else if (!cmd || !Object.hasOwn(SUBCOMMANDS, cmd)) {
  process.stderr.write(`gcs-skin: ${cmd ? `unknown command '${cmd}'` : 'missing command'}\n${usage()}\n`);
  process.exitCode = 2;
} else {
  let mod;
  try {
    mod = await import(new URL(SUBCOMMANDS[cmd].module, import.meta.url).href);
  } catch (e) {
    // A missing package (three and gcs-skin are peer dependencies: yarn berry, or npm --legacy-peer-deps, does not
    // install it) or a missing build (a git checkout before `npm run build:lib`).
    const pkg = e?.code === 'ERR_MODULE_NOT_FOUND' && /Cannot find package '([^']+)'/.exec(e.message)?.[1];
    process.stderr.write(pkg
      ? `gcs-skin: cannot load ${cmd}: the package '${pkg}' is not installed; install it beside @gcs-skin/cli (npm install ${pkg})\n`
      : `gcs-skin: cannot load ${SUBCOMMANDS[cmd].module} (${e.message}); run 'npm run build:lib' first\n`);
    process.exit(1);
  }
  process.exitCode = await mod.run(rest);
}
