// What skybake's node tools and checks share (tests/ktx2_crosscheck,
// shaders_runtime/translate, tests/runtime_webgpu): their exits (0, 1 with
// FAILED, 77 with SKIPPED, as ctest's SKIP_RETURN_CODE reads them), their
// `--name value` arguments, and the npm packages they pin, installed into a
// work directory (`npm ci`, skipped when the pinned versions are already
// there) and imported from it.

import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

export const SKIP = 77;

// skip(message) and fail(message) for the tool that does `what`.
export function toolExits(what) {
  return {
    skip(message) {
      console.log(`SKIPPED: ${what} not run: ${message}`);
      process.exit(SKIP);
    },
    fail(message) {
      console.error(`FAILED: ${message}`);
      process.exit(1);
    },
  };
}

// `--name value` pairs as { name: value }; fail() on anything else or a
// missing `required` name.
export function parseArgs(argv, required, fail) {
  const args = {};
  for (let i = 0; i < argv.length; i += 2) {
    if (!argv[i].startsWith('--') || i + 1 >= argv.length) fail(`bad arguments: ${argv.join(' ')}`);
    args[argv[i].slice(2)] = argv[i + 1];
  }
  for (const name of required) if (!args[name]) fail(`missing --${name}`);
  return args;
}

// npm errors that mean "no registry here", as opposed to a broken lock file.
const NETWORK_ERROR = /ENOTFOUND|EAI_AGAIN|ECONNREFUSED|ECONNRESET|ETIMEDOUT|ENETUNREACH|EHOSTUNREACH|socket hang up|network|fetch failed|E50[234]/i;

// Runs `npm ARGS` in `cwd`: skip(message) where npm or its registry is
// unavailable, fail(message) on any other error.
export function runNpm(args, cwd, { skip, fail }) {
  const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
  const run = spawnSync(npm, args, { cwd, encoding: 'utf8', timeout: 240000 });
  if (run.error && run.error.code === 'ENOENT') skip('npm is not installed');
  if (run.error && run.error.code === 'ETIMEDOUT') skip(`npm ${args[0]} timed out (registry unreachable?)`);
  if (run.error) fail(`cannot run npm: ${run.error.message}`);
  const output = `${run.stdout}\n${run.stderr}`.trim();
  if (run.status !== 0) {
    if (NETWORK_ERROR.test(output)) skip(`the npm registry is unavailable:\n${output}`);
    fail(`npm ${args[0]} failed:\n${output}`);
  }
}

// Installs the pinned dependencies of packageDir into workDir (npm ci, as
// runNpm reports its errors); returns them.
export function installPinned(packageDir, workDir, { skip, fail }) {
  fs.mkdirSync(workDir, { recursive: true });
  const dependencies = JSON.parse(fs.readFileSync(path.join(packageDir, 'package.json'), 'utf8')).dependencies;
  for (const file of ['package.json', 'package-lock.json']) {
    const source = fs.readFileSync(path.join(packageDir, file));
    const target = path.join(workDir, file);
    if (!fs.existsSync(target) || !fs.readFileSync(target).equals(source)) fs.writeFileSync(target, source);
  }
  const installedVersion = (name) => {
    const manifest = path.join(workDir, 'node_modules', name, 'package.json');
    return fs.existsSync(manifest) ? JSON.parse(fs.readFileSync(manifest, 'utf8')).version : null;
  };
  if (Object.entries(dependencies).some(([name, version]) => installedVersion(name) !== version)) {
    runNpm(['ci', '--no-audit', '--no-fund', '--loglevel=error', '--fetch-retries=1'], workDir, { skip, fail });
  }
  return dependencies;
}

// import() of a package installed in workDir.
export async function importInstalled(workDir, name) {
  const require = createRequire(path.join(workDir, 'package.json'));
  return import(pathToFileURL(require.resolve(name)).href);
}
