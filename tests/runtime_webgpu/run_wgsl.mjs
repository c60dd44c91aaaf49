// Runs a WGSL compute shader on Dawn (the npm package webgpu, pinned in
// package-lock.json and installed into <work-dir>) for
// tests/runtime_webgpu_test.cpp.
//
//   node run_wgsl.mjs --work-dir <dir> --job <dir>
//
// <job>/job.json names the shader (entry point "main", workgroup size 64),
// the inputs (float32 vec4s), the textures (float32 RGBA texels, x fastest,
// already representable as half floats) and the output file, which receives
// one vec4 of float32 per item. With "compile_only": true it names only the
// shader, which must compile and make a compute pipeline.
//
// Dawn finds no Vulkan adapter on this Mesa; it runs on OpenGL ES
// (EGL surfaceless, llvmpipe) at the WebGPU compatibility feature level.
// Without the optional feature float32-filterable (not offered there) a
// float texture can be filtered only as rgba16float, so the textures are
// uploaded in half precision, as a web engine without that feature must.
//
// Exit codes: 0 done, 1 an error (a shader that does not compile, say), 77
// skipped: npm, its registry or a WebGPU adapter is unavailable.

import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { importInstalled, installPinned, parseArgs, toolExits } from '../../scripts/node_tool.mjs';

const { skip, fail } = toolExits('WGSL');

// IEEE 754 binary16 bits of a float32 that is exactly representable as one.
function halfBits(value) {
  const f32 = new Float32Array([value]);
  const bits = new Uint32Array(f32.buffer)[0];
  const sign = (bits >>> 16) & 0x8000;
  const exponent = (bits >>> 23) & 0xff;
  const mantissa = bits & 0x7fffff;
  if (exponent === 0xff) return sign | 0x7c00 | (mantissa ? 0x200 : 0);
  const e = exponent - 127 + 15;
  if (e >= 0x1f) fail(`texel ${value} overflows half`);
  if (e <= 0) {
    if (e < -10) return sign;  // rounds to zero: only for values below half's range
    return sign | ((mantissa | 0x800000) >>> (14 - e));
  }
  return sign | (e << 10) | (mantissa >>> 13);
}

function readFloats(file) {
  const bytes = fs.readFileSync(file);
  return new Float32Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 4);
}

async function main() {
  const args = parseArgs(process.argv.slice(2), ['work-dir', 'job'], fail);
  const here = path.dirname(fileURLToPath(import.meta.url));
  installPinned(here, path.resolve(args['work-dir']), { skip, fail });
  const { create, globals } = await importInstalled(path.resolve(args['work-dir']), 'webgpu');
  Object.assign(globalThis, globals);

  const jobDir = path.resolve(args.job);
  const job = JSON.parse(fs.readFileSync(path.join(jobDir, 'job.json'), 'utf8'));
  process.env.EGL_PLATFORM ??= 'surfaceless';
  const gpu = create(['backend=opengles']);
  const adapter = await gpu.requestAdapter({ featureLevel: 'compatibility' });
  if (!adapter) skip('no WebGPU adapter (Dawn on OpenGL ES through EGL)');
  const device = await adapter.requestDevice();
  const errors = [];
  device.onuncapturederror = (event) => errors.push(event.error.message);

  const code = fs.readFileSync(path.join(jobDir, job.shader), 'utf8');
  const module = device.createShaderModule({ code });
  const messages = (await module.getCompilationInfo()).messages.filter((m) => m.type === 'error');
  if (messages.length) {
    fail(`the WGSL does not compile:\n${messages.map((m) => `${m.lineNum}:${m.linePos}: ${m.message}`).join('\n')}`);
  }
  if (job.compile_only) {
    device.pushErrorScope('validation');
    device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: 'main' } });
    const error = await device.popErrorScope();
    if (error) fail(`no compute pipeline: ${error.message}`);
    console.log('compiles');
    device.destroy();
    process.exit(0);
  }

  const entries = [];
  for (const t of job.textures) {
    const texels = readFloats(path.join(jobDir, t.file));
    const halves = new Uint16Array(texels.length);
    for (let i = 0; i < texels.length; ++i) halves[i] = halfBits(texels[i]);
    const size = [t.width, t.height, t.depth];
    const texture = device.createTexture({
      size,
      dimension: t.depth > 1 ? '3d' : '2d',
      format: 'rgba16float',
      usage: GPUTextureUsage.TEXTURE_BINDING | GPUTextureUsage.COPY_DST,
    });
    device.queue.writeTexture({ texture }, halves, { bytesPerRow: t.width * 8, rowsPerImage: t.height }, size);
    entries.push({ binding: t.binding, resource: texture.createView() });
  }
  const inputs = readFloats(path.join(jobDir, job.inputs));
  const inputBuffer = device.createBuffer({ size: inputs.byteLength, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST });
  device.queue.writeBuffer(inputBuffer, 0, inputs);
  const outputBytes = job.items * 16;
  const outputBuffer = device.createBuffer({ size: outputBytes, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
  const readback = device.createBuffer({ size: outputBytes, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
  entries.push({ binding: job.input_binding, resource: { buffer: inputBuffer } });
  entries.push({ binding: job.output_binding, resource: { buffer: outputBuffer } });
  // Linear filtering, clamped to the edge, one level: the runtime's README.
  const sampler = device.createSampler({ magFilter: 'linear', minFilter: 'linear' });
  entries.push({ binding: job.sampler_binding, resource: sampler });

  const pipeline = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: 'main' } });
  const bindGroup = device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries });
  const encoder = device.createCommandEncoder();
  const pass = encoder.beginComputePass();
  pass.setPipeline(pipeline);
  pass.setBindGroup(0, bindGroup);
  pass.dispatchWorkgroups(Math.ceil(job.items / 64));
  pass.end();
  encoder.copyBufferToBuffer(outputBuffer, 0, readback, 0, outputBytes);
  device.queue.submit([encoder.finish()]);
  await readback.mapAsync(GPUMapMode.READ);
  const outputs = new Float32Array(readback.getMappedRange().slice(0));
  readback.unmap();
  if (errors.length) fail(errors.join('\n'));
  fs.writeFileSync(path.join(jobDir, job.output), Buffer.from(outputs.buffer));
  console.log(`${adapter.info.description || 'WebGPU'} (Dawn, ${adapter.info.device}): ${job.items} items`);
  device.destroy();
  process.exit(0);
}

await main();
