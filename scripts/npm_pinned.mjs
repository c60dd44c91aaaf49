// Installs the npm packages a directory's package.json / package-lock.json
// pin into a work directory (`npm ci`, skipped when the pinned versions are
// already there) and imports them from it. Used by the node tools and checks
// that need an npm package (tests/ktx2_crosscheck, shaders_runtime/translate,
// tests/runtime_webgpu).

import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

// npm errors that mean "no registry here", as opposed to a broken lock file.
const NETWORK_ERROR = /ENOTFOUND|EAI_AGAIN|ECONNREFUSED|ECONNRESET|ETIMEDOUT|ENETUNREACH|EHOSTUNREACH|socket hang up|network|fetch failed|E50[234]/i;

// Calls skip(message) where npm or its registry is unavailable and
// fail(message) on any other error; returns the pinned dependencies.
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
    const npm = process.platform === 'win32' ? 'npm.cmd' : 'npm';
    const run = spawnSync(npm, ['ci', '--no-audit', '--no-fund', '--loglevel=error', '--fetch-retries=1'], {
      cwd: workDir,
      encoding: 'utf8',
      timeout: 240000,
    });
    if (run.error && run.error.code === 'ENOENT') skip('npm is not installed');
    if (run.error && run.error.code === 'ETIMEDOUT') skip('npm ci timed out (registry unreachable?)');
    if (run.error) fail(`cannot run npm: ${run.error.message}`);
    const output = `${run.stdout}\n${run.stderr}`.trim();
    if (run.status !== 0) {
      if (NETWORK_ERROR.test(output)) skip(`the npm registry is unavailable:\n${output}`);
      fail(`npm ci failed:\n${output}`);
    }
  }
  return dependencies;
}

// import() of a package installed in workDir.
export async function importInstalled(workDir, name) {
  const require = createRequire(path.join(workDir, 'package.json'));
  return import(pathToFileURL(require.resolve(name)).href);
}
