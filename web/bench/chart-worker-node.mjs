// @ts-check
// A decode pool's helper (src/chart-helper.js) on a Node worker thread, for
// bench/mesh-decode.mjs: what src/chart-worker.js is in a browser.
import { readFileSync } from 'node:fs';
import { parentPort, workerData } from 'node:worker_threads';
import { ChartHelper } from '../src/chart-helper.js';
import { VitrineCodec } from '../src/codec.js';

const port = /** @type {import('node:worker_threads').MessagePort} */ (parentPort);
const helper = new ChartHelper(await VitrineCodec.instantiate(readFileSync(workerData.wasm)));
port.on('message', (command) => {
  const { reply, transfer } = helper.handle(command);
  port.postMessage(reply, transfer);
});
