#!/usr/bin/env node
// gcs-skin command line: a table of subcommands, each a module (built into ../dist by
// `npm run build:lib`) exporting `run(argv) → Promise<exit code>` and `usage`.
const SUBCOMMANDS = {
  human: { module: '../dist/human/cli.js', about: 'write the default human character (mesh, skin, clips) as .glb' },
  report: { module: '../dist/cli/report.js', about: 'build every deformer on a glTF skinned model and report counts, timings, fidelity' },
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
    process.stderr.write(`gcs-skin: cannot load ${SUBCOMMANDS[cmd].module} (${e.message}); run 'npm run build:lib' first\n`);
    process.exit(1);
  }
  process.exitCode = await mod.run(rest);
}
