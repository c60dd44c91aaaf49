// Translates the GLSL runtime (definitions.glsl and the kRuntimeFunctionSources
// of snippet.h) into the other shading languages. The GLSL stays the one
// source of every function body; the translations are generated files.
//
//   node translate.mjs --out <dir> --work-dir <dir>
//   node translate.mjs --check <dir> --work-dir <dir>
//
// --check translates into a scratch folder and fails, naming the files, if
// <dir> (the committed shaders_runtime/generated) differs: a stale translation.
//
// - HLSL and MSL: glslang compiles the runtime, with reachability_main.glsl as
//   a compute entry point, to SPIR-V; spirv-cross translates it. Each
//   language's definitions (structs, constants) and functions are written as
//   two files, so that a bake's constants file goes between them as in GLSL.
//   spirv-cross drops the preprocessor, so the SKYBAKE_HAS_* switches are
//   recovered: the runtime is translated once more without each table, and a
//   function that disappears without a table is wrapped in `#if` on its flag.
// - WGSL: naga (the npm package naga-wasm, pinned in package-lock.json and
//   installed into <work-dir>) reads the GLSL with separate_samplers.glsl and
//   writes WGSL. WGSL has no preprocessor: the functions that need a table
//   carry a marker line instead, found the same way, by which the bake
//   leaves them out (snippet.cpp).
//
// Needs glslangValidator, spirv-cross, node and npm. Exit code 77: a tool or
// the npm registry is unavailable.

import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { importInstalled, installPinned, parseArgs, toolExits } from '../../scripts/node_tool.mjs';

const { skip, fail } = toolExits('runtime translation');
const here = path.dirname(fileURLToPath(import.meta.url));
const runtimeDir = path.dirname(here);

// The runtime's sources in their order of definition (snippet.h's
// kRuntimeFunctionSources, read from there so the two cannot differ).
function functionSources() {
  const header = fs.readFileSync(path.join(runtimeDir, 'snippet.h'), 'utf8');
  const list = header.match(/kRuntimeFunctionSources\[\] = \{([^}]*)\}/);
  if (!list) fail('kRuntimeFunctionSources not found in snippet.h');
  return [...list[1].matchAll(/"([^"]+)"/g)].map((m) => m[1]);
}

const read = (file) => fs.readFileSync(path.join(runtimeDir, file), 'utf8');

// The table switches, and what turning each off also turns off.
const FLAGS = {
  SKYBAKE_HAS_SCATTERING_TEXTURE: ['SKYBAKE_HAS_AERIAL_PERSPECTIVE'],
  SKYBAKE_HAS_IRRADIANCE_TEXTURE: [],
  SKYBAKE_HAS_AERIAL_PERSPECTIVE: [],
};

// The translations made to recover the switches: all tables, and without
// each table (and what needs it).
function variants() {
  const result = { all: [] };
  for (const [flag, implied] of Object.entries(FLAGS)) result[flag] = [flag, ...implied];
  return result;
}

// The switches function `name` needs: those without which it is not in the
// translation (namesWithout[flag]: the function names translated without
// that table). Aerial perspective implies the scattering table.
function requiredFlags(name, namesWithout) {
  const needs = Object.keys(FLAGS).filter((flag) => !namesWithout[flag].has(name));
  return needs.includes('SKYBAKE_HAS_AERIAL_PERSPECTIVE')
    ? needs.filter((flag) => flag !== 'SKYBAKE_HAS_SCATTERING_TEXTURE')
    : needs;
}

// The runtime as one GLSL 4.50 compute shader; `off` lists the switches set to 0.
function runtimeGlsl(off, middle, tail) {
  const defines = Object.keys(FLAGS).map((flag) => `#define ${flag} ${off.includes(flag) ? 0 : 1}\n`);
  return ['#version 450\n', read('definitions.glsl'), middle, ...defines, ...functionSources().map(read), tail].join('');
}

function run(command, args, what) {
  const result = spawnSync(command, args, { encoding: 'utf8' });
  if (result.error && result.error.code === 'ENOENT') skip(`${command} is not installed`);
  if (result.error) fail(`cannot run ${command}: ${result.error.message}`);
  if (result.status !== 0) fail(`${what} failed:\n${result.stdout}\n${result.stderr}`);
  return result.stdout;
}

// Splits C-like source into its top-level items: a preprocessor line, a
// declaration ending in ';', or a definition ending with its closing brace.
function topLevelItems(text) {
  const items = [];
  let current = [];
  let depth = 0;
  for (const line of text.split('\n')) {
    if (depth === 0 && current.length === 0 && line.trim() === '') continue;
    current.push(line);
    for (const c of line) depth += c === '{' ? 1 : c === '}' ? -1 : 0;
    const trimmed = line.trim();
    if (depth === 0 && (trimmed.startsWith('#') || /[;}]$/.test(trimmed) || trimmed.startsWith('//'))) {
      items.push(current.join('\n'));
      current = [];
    }
  }
  if (current.some((line) => line.trim() !== '')) fail(`unbalanced translation output:\n${current.join('\n')}`);
  return items;
}

// The function an item defines, or null.
function definedFunction(item) {
  if (/^\s*(struct|template|#|\/\/)/.test(item) || !item.includes('{')) return null;
  // Without attributes: HLSL's [numthreads(...)] lines, MSL's __attribute__((...)).
  const signature = item.slice(0, item.indexOf('{')).replace(/^\[.*\]$/gm, '').replace(/__attribute__\(\([^)]*\)\)/g, '');
  const match = signature.match(/\b(\w+)\s*\([^;=]*\)\s*$/);
  return match ? match[1] : null;
}

// What of spirv-cross's output belongs to the reachability main rather than
// to the runtime: the entry points, their inputs and the resources.
function isHarness(item, name) {
  return ['main', 'comp_main', 'main0'].includes(name) || /register\(|gl_WorkGroupSize|SPIRV_Cross_|\bValues\b|kernel /.test(item);
}

// Splits one spirv-cross translation into definitions and functions (name -> text).
function splitSpirvCross(text) {
  const definitions = [];
  const functions = new Map();
  for (const item of topLevelItems(text)) {
    const name = definedFunction(item);
    if (isHarness(item, name)) continue;
    if (name) functions.set(name, item);
    else definitions.push(item);
  }
  return { definitions, functions };
}

function spirvCross(spirv, language) {
  const args = language === 'hlsl' ? ['--hlsl', '--shader-model', '50'] : ['--msl'];
  return run('spirv-cross', [spirv, ...args], `spirv-cross --${language}`);
}

function header(comment, file, how) {
  return `${comment} skybake runtime, ${file}: generated by shaders_runtime/translate/translate.mjs from the GLSL runtime\n` +
    `${comment} (${how}). Do not edit: edit the GLSL and run scripts/translate_runtime.sh.\n`;
}

// HLSL and MSL through SPIR-V and spirv-cross, with #if guards.
function translateThroughSpirv(workDir) {
  const tail = read('translate/reachability_main.glsl');
  const translations = { hlsl: {}, msl: {} };
  for (const [variant, off] of Object.entries(variants())) {
    const source = path.join(workDir, `runtime_${variant}.comp`);
    const spirv = path.join(workDir, `runtime_${variant}.spv`);
    fs.writeFileSync(source, runtimeGlsl(off, '', tail));
    run('glslangValidator', ['-V', '-g', '-o', spirv, source], `glslangValidator ${variant}`);
    for (const language of Object.keys(translations)) {
      translations[language][variant] = splitSpirvCross(spirvCross(spirv, language));
    }
  }
  const files = {};
  for (const [language, byVariant] of Object.entries(translations)) {
    const all = byVariant.all;
    const namesWithout = Object.fromEntries(Object.keys(FLAGS).map((flag) => [flag, byVariant[flag].functions]));
    const functions = [];
    for (const [name, text] of all.functions) {
      const needs = requiredFlags(name, namesWithout);
      functions.push(needs.length ? `#if ${needs.join(' && ')}\n${text}\n#endif` : text);
    }
    const extension = language === 'hlsl' ? 'hlsl' : 'metal';
    const how = `glslang to SPIR-V, spirv-cross --${language}`;
    files[`definitions.${extension}`] = header('//', `definitions.${extension}`, how) + all.definitions.join('\n\n') + '\n';
    files[`functions.${extension}`] = header('//', `functions.${extension}`, how) +
      '// Include after definitions and the bake\'s atmosphere_constants; the SKYBAKE_HAS_* switches come from there.\n' +
      functions.join('\n\n') + '\n';
  }
  return files;
}

// WGSL through naga's GLSL front end. WGSL has no preprocessor, so each
// function that needs a table is marked with a line
// `// skybake: needs SKYBAKE_HAS_... [&& ...]` before it, which the bake reads
// to leave the function out of a scene's set that lacks the table.
async function translateWgsl(workDir) {
  installPinned(here, workDir, { skip, fail });
  const naga = await importInstalled(workDir, 'naga-wasm');
  const translate = (off) => {
    const source = runtimeGlsl(off, read('translate/separate_samplers.glsl'),
                               'layout(local_size_x = 1) in;\nvoid main() {}\n');
    try {
      const module = naga.parseGlsl(source, { stage: 'compute' });
      return topLevelItems(naga.writeWgsl(module, naga.validate(module)))
        .filter((item) => !/^fn main(_1)?\(|^@compute|var skybake_linear_sampler/m.test(item));
    } catch (error) {
      return fail(`naga: ${error.formatted ?? error}`);
    }
  };
  const functionName = (item) => (item.match(/^fn (\w+)\(/m) || [])[1];
  const namesWithout = {};
  for (const [variant, off] of Object.entries(variants())) {
    if (variant !== 'all') namesWithout[variant] = new Set(translate(off).map(functionName).filter(Boolean));
  }
  const items = translate([]).map((item) => {
    const name = functionName(item);
    const needs = name ? requiredFlags(name, namesWithout) : [];
    return needs.length ? `// skybake: needs ${needs.join(' && ')}\n${item}` : item;
  });
  return {
    'functions.wgsl': header('//', 'functions.wgsl', `naga ${naga.nagaVersion}, GLSL front end, WGSL back end`) +
      '// Declare `@group(G) @binding(B) var skybake_linear_sampler: sampler;` (linear filtering, clamp to edge)\n' +
      '// in your module; the bake\'s atmosphere_constants.wgsl holds ATMOSPHERE and the SKYBAKE_HAS_* flags.\n' +
      items.join('\n\n') + '\n',
  };
}

async function main() {
  const args = parseArgs(process.argv.slice(2), ['work-dir'], fail);
  if (!args.out === !args.check) fail('give one of --out and --check');
  const workDir = path.resolve(args['work-dir']);
  fs.mkdirSync(workDir, { recursive: true });
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), 'skybake-translate-'));
  try {
    const files = { ...translateThroughSpirv(scratch), ...(await translateWgsl(workDir)) };
    if (args.check) {
      const committed = fs.readdirSync(args.check).sort();
      const stale = Object.keys(files).filter(
        (name) => !committed.includes(name) || fs.readFileSync(path.join(args.check, name), 'utf8') !== files[name]);
      const extra = committed.filter((name) => !(name in files));
      if (stale.length || extra.length) {
        fail(`${args.check} is stale: ${[...stale, ...extra].join(', ')} differ from a fresh translation; ` +
             'run scripts/translate_runtime.sh');
      }
      console.log(`${Object.keys(files).join(', ')}: identical to a fresh translation`);
      return;
    }
    fs.mkdirSync(args.out, { recursive: true });
    for (const [name, text] of Object.entries(files)) fs.writeFileSync(path.join(args.out, name), text);
    console.log(`wrote ${Object.keys(files).join(', ')} to ${args.out}`);
  } finally {
    fs.rmSync(scratch, { recursive: true, force: true });
  }
}

await main();
