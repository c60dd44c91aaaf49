// Installs the peer runtime that tests/runtime_cost.cpp measures beside
// skybake's, and prints the folder holding its GLSL.
//
//   node install_peer.mjs --work-dir <dir>
//
// The peer is Bruneton's 2017 runtime as the npm package
// @takram/three-atmosphere ships it (package/src/shaders/bruneton/
// definitions.glsl, common.glsl, runtime.glsl), pinned in package-lock.json
// and installed into <work-dir> with `npm ci`. Only its own dependencies are
// installed: its peer dependencies (react, three, postprocessing, ...) are
// what a three.js application brings and no GLSL needs them, so npm runs with
// legacy-peer-deps (the lock file was made that way) and runs no install
// scripts. Its code is read from there at run time and never copied into
// skybake's tree.
//
// Exit codes: 0 with the folder on standard output, 1 an error, 77 skipped
// (npm or its registry is unavailable), as scripts/node_tool.mjs defines them.

import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { installPinned, parseArgs, toolExits } from '../../scripts/node_tool.mjs';

const { skip, fail } = toolExits('the peer runtime (@takram/three-atmosphere)');
const PACKAGE = '@takram/three-atmosphere';
const SHADERS = ['definitions.glsl', 'common.glsl', 'runtime.glsl'];

const args = parseArgs(process.argv.slice(2), ['work-dir'], fail);
const here = path.dirname(fileURLToPath(import.meta.url));
// npm ci reads these from the environment: without legacy-peer-deps it
// would find the peer dependencies missing from the lock file and refuse.
process.env.npm_config_legacy_peer_deps = 'true';
process.env.npm_config_ignore_scripts = 'true';
const workDir = path.resolve(args['work-dir']);
installPinned(here, workDir, { skip, fail });
const shaders = path.join(workDir, 'node_modules', ...PACKAGE.split('/'), 'src', 'shaders', 'bruneton');
for (const file of SHADERS) {
  if (!fs.existsSync(path.join(shaders, file))) fail(`${PACKAGE} has no ${file} in ${shaders}`);
}
console.log(shaders);
