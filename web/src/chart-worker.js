// @ts-check
/**
 * A decode pool's helper worker (chart-helper.js): the page starts it with
 * `{ type: 'init', module, port }`, the compiled codec and its end of a
 * channel to the decode worker, which sends it the stream's payloads.
 */

import { VitrineCodec } from './codec.js';
import { ChartHelper } from './chart-helper.js';

const scope = /** @type {DedicatedWorkerGlobalScope} */ (/** @type {unknown} */ (self));

scope.onmessage = async (/** @type {MessageEvent<{ type: 'init', module: WebAssembly.Module, port: MessagePort }>} */ event) => {
  if (event.data.type !== 'init') return;
  const { module, port } = event.data;
  /** @type {ChartHelper | null} */
  let helper = null;
  /** @type {string | null} */
  let failed = null;
  try {
    helper = new ChartHelper(await VitrineCodec.instantiate(module));
  } catch (error) {
    failed = `a decode helper did not start: ${error}`;
  }
  // Messages wait on the port until this handler is set.
  port.onmessage = (/** @type {MessageEvent<import('./chart-helper.js').HelperCommand>} */ message) => {
    if (!helper) {
      port.postMessage({ type: 'error', message: failed });
      return;
    }
    const { reply, transfer } = helper.handle(message.data);
    port.postMessage(reply, transfer);
  };
};
