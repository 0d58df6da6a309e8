// The renderer asks for multisampling only on a GPU (src/rasteriser.js).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { isSoftwareRasteriser, probeRenderer } from '../src/rasteriser.js';

test('CPU rasterisers are told from GPUs by their renderer strings', () => {
  const software = [
    'ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) (0x0000C0DE)), SwiftShader driver)',
    'Google SwiftShader',
    'llvmpipe (LLVM 15.0.6, 256 bits)',
    'ANGLE (Microsoft, Microsoft Basic Render Driver Direct3D11 vs_5_0 ps_5_0, D3D11)',
    'Mesa softpipe',
    'ANGLE (Mesa, lavapipe, Vulkan)',
  ];
  const gpus = [
    'ANGLE (Intel, Mesa Intel(R) UHD Graphics 620 (KBL GT2), OpenGL 4.6)',
    'Apple GPU',
    'ANGLE (NVIDIA, NVIDIA GeForce RTX 3060 Direct3D11 vs_5_0 ps_5_0, D3D11)',
    'Adreno (TM) 650',
    'Mali-G78',
    'WebKit WebGL',
    '',
  ];
  for (const name of software) assert.equal(isSoftwareRasteriser(name), true, name);
  for (const name of gpus) assert.equal(isSoftwareRasteriser(name), false, name);
});

test('without WebGL2 the probe says so instead of throwing', () => {
  // Node has neither OffscreenCanvas nor a document.
  assert.equal(probeRenderer(), null);
});
