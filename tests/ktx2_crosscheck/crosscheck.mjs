// Cross-checks skybake's KTX2 writer with an independent parser, ktx-parse,
// and an independent Zstandard decoder, fzstd (both pinned in package.json /
// package-lock.json).
//
//   node crosscheck.mjs --tests-exe <skybake_tests> --skybake-exe <skybake> --work-dir <dir>
//
// 1. Runs the gtest case Ktx2CrossCheck.WritesSampleSet, which writes one
//    sample per format, 2D and 3D, with extra keys, plus the raw level bytes
//    and a manifest of what each file is meant to hold.
// 2. Installs ktx-parse into <dir> with `npm ci` (reused when already there).
// 3. Reads every sample with ktx-parse and compares the header, the Data
//    Format Descriptor (expected values derived here from the KTX 2.0 and
//    Khronos Data Format specifications, not from skybake), the key/value
//    data and the level, then re-serialises it with ktx-parse and requires
//    the same bytes: an independent writer lays out the file identically.
// 4. Runs real bakes (`skybake bake --format ktx2`: float, half, and single
//    Mie packed into alpha) and checks every KTX2 file their manifests list:
//    SHA-256 and size against the manifest (node:crypto), header and DFD as
//    above, the key/value data against the manifest's description of the
//    table, every texel finite and non-negative (decoded here, halves too),
//    and ktx-parse's byte-for-byte re-serialisation. One set is
//    zstd-supercompressed (--ktx2-supercompression): its levels, inflated by
//    an independent decoder (fzstd), must equal the float set's bytes.
//
// Exit codes: 0 all agree, 1 a disagreement or error, 77 skipped because npm
// or the npm registry is unavailable (ctest SKIP_RETURN_CODE).

import { spawnSync } from 'node:child_process';
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { importInstalled, installPinned, parseArgs, toolExits } from '../../scripts/node_tool.mjs';

const { skip, fail } = toolExits('ktx2 cross-check');

function writeSamples(testsExe, sampleDir) {
  fs.rmSync(sampleDir, { recursive: true, force: true });
  fs.mkdirSync(sampleDir, { recursive: true });
  const run = spawnSync(testsExe, ['--gtest_filter=Ktx2CrossCheck.WritesSampleSet'], {
    env: { ...process.env, SKYBAKE_KTX2_SAMPLE_DIR: sampleDir },
    encoding: 'utf8',
  });
  if (run.error) fail(`cannot run ${testsExe}: ${run.error.message}`);
  if (run.status !== 0) fail(`writing the samples failed:\n${run.stdout}\n${run.stderr}`);
  if (!/\[ {2}PASSED {2}\] 1 test/.test(run.stdout)) fail(`the sample writer did not run:\n${run.stdout}`);
}

function installParser(workDir) {
  const here = path.dirname(fileURLToPath(import.meta.url));
  return installPinned(here, workDir, { skip, fail })['ktx-parse'];
}

// ktx-parse, with fzstd's Zstandard decoder as parser.inflateZstd.
async function importParser(workDir) {
  const parser = await importInstalled(workDir, 'ktx-parse');
  const fzstd = await importInstalled(workDir, 'fzstd');
  return { ...parser, inflateZstd: fzstd.decompress };
}

// --- What the specifications require for skybake's four formats -----------

// VkFormat values (Vulkan specification, enum VkFormat).
const FORMATS = {
  76: { name: 'VK_FORMAT_R16_SFLOAT', channels: 1, bits: 16 },
  97: { name: 'VK_FORMAT_R16G16B16A16_SFLOAT', channels: 4, bits: 16 },
  100: { name: 'VK_FORMAT_R32_SFLOAT', channels: 1, bits: 32 },
  109: { name: 'VK_FORMAT_R32G32B32A32_SFLOAT', channels: 4, bits: 32 },
};

function float32BitsAsInt32(value) {
  const view = new DataView(new ArrayBuffer(4));
  view.setFloat32(0, value, true);
  return view.getInt32(0, true);
}

// Basic Data Format Descriptor for an unpacked little-endian signed float
// format (Khronos Data Format Specification 1.4, chapter 5).
function expectedDfd(format) {
  const rgbsdaIds = [0, 1, 2, 15]; // R, G, B, A
  const samples = [];
  for (let i = 0; i < format.channels; i++) {
    samples.push({
      bitOffset: i * format.bits,
      bitLength: format.bits - 1, // stored as length - 1
      channelType: rgbsdaIds[i] | 0x80 | 0x40, // FLOAT | SIGNED qualifiers
      samplePosition: [0, 0, 0, 0],
      // Float channels carry float bounds; signed range -1..1. ktx-parse reads
      // the words as int32 because the SIGNED bit is set.
      sampleLower: float32BitsAsInt32(-1.0),
      sampleUpper: float32BitsAsInt32(1.0),
    });
  }
  return {
    vendorId: 0,
    descriptorType: 0,
    versionNumber: 2,
    colorModel: 1, // KHR_DF_MODEL_RGBSDA
    colorPrimaries: 1, // KHR_DF_PRIMARIES_BT709
    transferFunction: 1, // KHR_DF_TRANSFER_LINEAR
    flags: 0, // KHR_DF_FLAG_ALPHA_STRAIGHT
    texelBlockDimension: [0, 0, 0, 0],
    bytesPlane: [(format.channels * format.bits) / 8, 0, 0, 0, 0, 0, 0, 0],
    samples,
  };
}

function gcd(a, b) {
  return b === 0 ? a : gcd(b, a % b);
}

function compareBytes(a, b) {
  const n = Math.min(a.length, b.length);
  for (let i = 0; i < n; i++) if (a[i] !== b[i]) return i;
  return a.length === b.length ? -1 : n;
}

function checkSample(parser, sampleDir, entry, problems) {
  const problem = (what) => problems.push(`${entry.file}: ${what}`);
  const expectEqual = (what, actual, expected) => {
    const a = JSON.stringify(actual);
    const e = JSON.stringify(expected);
    if (a !== e) problem(`${what} is ${a}, expected ${e}`);
  };

  const buffer = fs.readFileSync(path.join(sampleDir, entry.file));
  const bytes = new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  let container;
  try {
    container = parser.read(bytes);
  } catch (error) {
    problem(`ktx-parse cannot read it: ${error.message}`);
    return;
  }
  const format = FORMATS[entry.vkFormat];
  if (!format) {
    problem(`manifest names unknown vkFormat ${entry.vkFormat}`);
    return;
  }

  // Header (KTX 2.0 §3.2-§3.8).
  expectEqual('vkFormat', container.vkFormat, entry.vkFormat);
  expectEqual('typeSize', container.typeSize, format.bits / 8);
  expectEqual('pixelWidth', container.pixelWidth, entry.pixelWidth);
  expectEqual('pixelHeight', container.pixelHeight, entry.pixelHeight);
  expectEqual('pixelDepth', container.pixelDepth, entry.pixelDepth);
  expectEqual('layerCount', container.layerCount, 0);
  expectEqual('faceCount', container.faceCount, 1);
  expectEqual('levelCount', container.levelCount, entry.levelCount);
  expectEqual('supercompressionScheme', container.supercompressionScheme, 0);
  if (container.globalData) problem('has supercompression global data');

  // Data Format Descriptor.
  expectEqual('dataFormatDescriptor count', container.dataFormatDescriptor.length, 1);
  const expected = expectedDfd(format);
  const dfd = container.dataFormatDescriptor[0] || {};
  for (const field of Object.keys(expected)) expectEqual(`DFD ${field}`, dfd[field], expected[field]);

  // Level (KTX 2.0 §3.9.7, §3.13).
  expectEqual('levels.length', container.levels.length, 1);
  const level = container.levels[0];
  if (level) {
    expectEqual('level byteLength', level.levelData.byteLength, entry.levelByteLength);
    expectEqual('level uncompressedByteLength', level.uncompressedByteLength, entry.levelByteLength);
    const texelSize = (format.channels * format.bits) / 8;
    const alignment = (texelSize * 4) / gcd(texelSize, 4); // lcm(texel size, 4)
    const offset = level.levelData.byteOffset - bytes.byteOffset;
    if (offset % alignment !== 0) problem(`level offset ${offset} is not a multiple of ${alignment}`);
    const raw = fs.readFileSync(path.join(sampleDir, entry.levelData));
    const at = compareBytes(level.levelData, raw);
    if (at >= 0) problem(`level data differs from the texture data at byte ${at}`);
  }

  // Key/value data (KTX 2.0 §3.11): ktx-parse returns KTX* values as strings
  // without their NUL and other values as raw bytes, NUL included.
  const keys = Object.keys(container.keyValue);
  const expectedKeys = Object.keys(entry.keyValue).sort((a, b) => Buffer.compare(Buffer.from(a), Buffer.from(b)));
  expectEqual('keys in file order', keys, expectedKeys);
  for (const key of expectedKeys) {
    const value = container.keyValue[key];
    if (value === undefined) continue;
    if (/^ktx/i.test(key)) {
      expectEqual(`value of ${key}`, value, entry.keyValue[key]);
    } else {
      const wanted = Buffer.concat([Buffer.from(entry.keyValue[key], 'utf8'), Buffer.from([0])]);
      if (compareBytes(value, wanted) >= 0) problem(`value of ${key} is [${Array.from(value)}], expected [${Array.from(wanted)}]`);
    }
  }

  // An independent writer must lay the same container out byte for byte.
  if (problems.length === 0) {
    const rewritten = parser.write(container, { keepWriter: true });
    const at = compareBytes(rewritten, bytes);
    if (at >= 0) problem(`ktx-parse re-serialises it differently from byte ${at} (${rewritten.length} vs ${bytes.length} bytes)`);
  }
}

// --- Files written by a real bake ----------------------------------------------

const SMALL_BAKE = ['--transmittance-size', '64', '16', '--irradiance-size', '16', '4', '--scattering-size', '8', '32',
  '8', '4', '--ray-samples', '32', '--sphere-samples', '8', '--orders', '2'];

function bake(skybakeExe, outDir, extra) {
  const run = spawnSync(skybakeExe, ['bake', 'earth', '-q', '--format', 'ktx2', '-o', outDir, ...SMALL_BAKE, ...extra], {
    encoding: 'utf8',
  });
  if (run.error) fail(`cannot run ${skybakeExe}: ${run.error.message}`);
  if (run.status !== 0) fail(`skybake bake ${extra.join(' ')} failed:\n${run.stderr}`);
}

// IEEE 754 binary16, straight from the definition.
function halfToFloat(h) {
  const sign = h & 0x8000 ? -1 : 1;
  const e = (h >> 10) & 0x1f;
  const m = h & 0x3ff;
  if (e === 0) return sign * m * 2 ** -24;
  if (e === 31) return m ? NaN : sign * Infinity;
  return sign * (1 + m / 1024) * 2 ** (e - 15);
}

// Checks one KTX2 file of a baked set; returns its level, inflated where the
// file is zstd-supercompressed.
function checkBakedFile(parser, setDir, manifest, table, entry, problems) {
  const problem = (what) => problems.push(`${path.basename(setDir)}/${entry.file}: ${what}`);
  const expectEqual = (what, actual, expected) => {
    const a = JSON.stringify(actual);
    const e = JSON.stringify(expected);
    if (a !== e) problem(`${what} is ${a}, expected ${e}`);
  };
  const buffer = fs.readFileSync(path.join(setDir, entry.file));
  const bytes = new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  expectEqual('size in bytes', bytes.length, entry.bytes);
  expectEqual('sha256', crypto.createHash('sha256').update(buffer).digest('hex'), entry.sha256);

  let container;
  try {
    container = parser.read(bytes);
  } catch (error) {
    problem(`ktx-parse cannot read it: ${error.message}`);
    return null;
  }
  const zstd = entry.storage.endsWith(', zstd');
  const half = entry.pixel_type === 'half';
  const vkFormat = half ? 97 : 109;
  const format = FORMATS[vkFormat];
  const is3d = entry.size.length === 3;
  expectEqual('vkFormat', container.vkFormat, vkFormat);
  expectEqual('typeSize', container.typeSize, format.bits / 8);
  expectEqual('pixelWidth', container.pixelWidth, entry.size[0]);
  expectEqual('pixelHeight', container.pixelHeight, entry.size[1]);
  expectEqual('pixelDepth', container.pixelDepth, is3d ? entry.size[2] : 0);
  expectEqual('layerCount', container.layerCount, 0);
  expectEqual('faceCount', container.faceCount, 1);
  expectEqual('levelCount', container.levelCount, 1);
  // KTX 2.0 supercompressionScheme: 2 is Zstandard; the DFD keeps the
  // pre-deflation values (bytesPlane included).
  expectEqual('supercompressionScheme', container.supercompressionScheme, zstd ? 2 : 0);
  const expectedDescriptor = expectedDfd(format);
  const dfd = container.dataFormatDescriptor[0] || {};
  for (const field of Object.keys(expectedDescriptor)) expectEqual(`DFD ${field}`, dfd[field], expectedDescriptor[field]);

  // Key/value data: sorted by code point, and saying what the manifest says.
  const keys = Object.keys(container.keyValue);
  expectEqual('keys in file order', keys, [...keys].sort((a, b) => Buffer.compare(Buffer.from(a), Buffer.from(b))));
  const text = (key) => {
    const value = container.keyValue[key];
    if (value === undefined) return undefined;
    if (typeof value === 'string') return value;
    return new TextDecoder('utf-8', { fatal: true }).decode(value).replace(/\0$/, '');
  };
  expectEqual('KTXorientation', text('KTXorientation'), is3d ? 'rdi' : 'rd');
  if (!/^skybake /.test(text('KTXwriter') || '')) problem(`KTXwriter is ${JSON.stringify(text('KTXwriter'))}`);
  expectEqual('skybake.table', text('skybake.table'), table.name);
  expectEqual('skybake.encoding', text('skybake.encoding'), table.encoding);
  expectEqual('skybake.units', text('skybake.units'), table.units);
  expectEqual('skybake.size', text('skybake.size'), entry.size.join('x'));
  expectEqual('skybake.layout', text('skybake.layout'), table.layout);
  expectEqual('skybake.channels', text('skybake.channels'), table.channels.map((c) => c.name).join(','));
  expectEqual('skybake.wavelengths_nm', (text('skybake.wavelengths_nm') || '').split(',').map(Number),
    manifest.wavelengths_nm);
  let parameters;
  try {
    parameters = JSON.parse(text('skybake.parameters'));
  } catch (error) {
    problem(`skybake.parameters is not JSON: ${error.message}`);
  }
  expectEqual('skybake.parameters', parameters, manifest.parameters);
  if (text('skybake.atmosphere') !== manifest.atmosphere_toml) problem('skybake.atmosphere differs from the manifest');

  // Level: every texel finite and non-negative; an RGB table's alpha is 0.
  const level = container.levels[0];
  const texels = entry.size.reduce((a, b) => a * b, 1);
  const bytesPerTexel = (format.channels * format.bits) / 8;
  if (!level) {
    problem('no level');
    return null;
  }
  expectEqual('level uncompressedByteLength', level.uncompressedByteLength, texels * bytesPerTexel);
  let data = level.levelData;
  if (zstd) {
    try {
      data = parser.inflateZstd(level.levelData);
    } catch (error) {
      problem(`fzstd cannot inflate the level: ${error.message}`);
      return null;
    }
  }
  expectEqual('level bytes (inflated)', data.byteLength, texels * bytesPerTexel);
  const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const meaningful = table.channels.length;
  let bad = 0;
  for (let i = 0; i < texels * 4 && (i + 1) * (format.bits / 8) <= data.byteLength; i++) {
    const value = half ? halfToFloat(view.getUint16(i * 2, true)) : view.getFloat32(i * 4, true);
    const padding = i % 4 >= meaningful;
    if (!Number.isFinite(value) || value < 0 || (padding && value !== 0)) {
      if (bad++ < 3) problem(`texel ${Math.floor(i / 4)} channel ${i % 4} is ${value}`);
    }
  }
  if (bad > 3) problem(`${bad} bad values in all`);

  const rewritten = parser.write(container, { keepWriter: true });
  const at = compareBytes(rewritten, bytes);
  if (at >= 0) problem(`ktx-parse re-serialises it differently from byte ${at}`);
  return data;
}

function checkBakedSets(parser, skybakeExe, workDir) {
  const bakedDir = path.join(workDir, 'baked');
  fs.rmSync(bakedDir, { recursive: true, force: true });
  const variants = {
    float: [],
    half: ['--half'],
    'pack-mie': ['--pack-mie'],
    zstd: ['--ktx2-supercompression', 'zstd:9'],
  };
  const problems = [];
  const levels = {};  // variant -> table -> level bytes (inflated)
  let files = 0;
  for (const [name, extra] of Object.entries(variants)) {
    const setDir = path.join(bakedDir, name);
    bake(skybakeExe, setDir, extra);
    const manifest = JSON.parse(fs.readFileSync(path.join(setDir, 'skybake.json'), 'utf8'));
    levels[name] = {};
    for (const table of manifest.tables) {
      for (const entry of table.files) {
        if (entry.format !== 'ktx2') continue;
        const before = problems.length;
        levels[name][table.name] = checkBakedFile(parser, setDir, manifest, table, entry, problems);
        files++;
        console.log(`${problems.length === before ? 'ok  ' : 'FAIL'} baked/${name}/${entry.file}`);
      }
    }
  }
  // float, half and zstd: four tables each; packed single Mie: three.
  if (files !== 15) problems.push(`expected 15 KTX2 files in the baked sets' manifests, found ${files}`);
  // The same bake with and without supercompression: the inflated levels are
  // the float set's bytes exactly.
  for (const [tableName, level] of Object.entries(levels.zstd)) {
    const plain = levels.float[tableName];
    const at = level && plain ? compareBytes(level, plain) : -1;
    if (at >= 0) problems.push(`baked/zstd/${tableName}.ktx2: inflated level differs from the float set's at byte ${at}`);
  }
  return { problems, files };
}

async function main() {
  const args = parseArgs(process.argv.slice(2), ['tests-exe', 'skybake-exe', 'work-dir'], fail);
  const workDir = path.resolve(args['work-dir']);
  fs.mkdirSync(workDir, { recursive: true });
  const sampleDir = path.join(workDir, 'samples');

  writeSamples(path.resolve(args['tests-exe']), sampleDir);
  const version = installParser(workDir);
  const parser = await importParser(workDir);

  const manifest = JSON.parse(fs.readFileSync(path.join(sampleDir, 'manifest.json'), 'utf8'));
  if (!Array.isArray(manifest) || manifest.length === 0) fail('the sample manifest lists no files');
  const problems = [];
  for (const entry of manifest) {
    const before = problems.length;
    checkSample(parser, sampleDir, entry, problems);
    console.log(`${problems.length === before ? 'ok  ' : 'FAIL'} ${entry.file}`);
  }
  const baked = checkBakedSets(parser, path.resolve(args['skybake-exe']), workDir);
  problems.push(...baked.problems);
  if (problems.length > 0) fail(`ktx-parse ${version} disagrees:\n  ${problems.join('\n  ')}`);
  console.log(`ktx2 cross-check: ${manifest.length} sample files and ${baked.files} baked files read by ktx-parse ${version}; header, DFD, key/value data and level agree (zstd levels inflated by fzstd equal the uncompressed bake's), and ktx-parse re-serialises them byte for byte`);
}

main().catch((error) => fail(error.stack || String(error)));
