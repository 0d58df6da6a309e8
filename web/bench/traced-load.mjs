// @ts-check
// One cold load of a viewer page under a DevTools trace, shared by
// viewer-bench.mjs (tables) and trace-main.mjs (finding where time goes).

const MBIT = 1_000_000 / 8;

/**
 * Loads `url` in a new page with the HTTP cache off and, when `mbits` is
 * set, the network emulated at that bandwidth (20 ms latency); traces it
 * with `categories` until the viewer has settled (complete or capped) and
 * the GPU has drawn the last frame. The page says when it is done through
 * the console, so no DevTools evaluation (which runs on the main thread)
 * falls inside the trace. A viewer that fails (`vitrine-error`: say, a
 * server whose stream format the WASM decoder does not read) or does not
 * settle within `timeoutMs` ends the load with an error that says so,
 * instead of a benchmark that waits forever.
 * @param {import('playwright-core').BrowserContext} context
 * @param {string} url
 * @param {{ mbits?: number | null, categories: string[], initScript?: () => void, collect?: (page: import('playwright-core').Page) => Promise<any>, timeoutMs?: number }} options
 *   `initScript` also runs in the page before its scripts; `collect` reads
 *   the page after the load, before it closes
 */
export async function tracedLoad(context, url, { mbits = null, categories, initScript, collect, timeoutMs = 300_000 }) {
  const page = await context.newPage();
  const cdp = await context.newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.setCacheDisabled', { cacheDisabled: true });
  if (mbits) {
    await cdp.send('Network.emulateNetworkConditions', {
      offline: false,
      latency: 20,
      downloadThroughput: mbits * MBIT,
      uploadThroughput: mbits * MBIT,
    });
  }
  if (initScript) await page.addInitScript(initScript);
  await page.addInitScript(() => {
    document.addEventListener('vitrine-level', () => {
      const status = /** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state.status;
      if (status === 'complete' || status === 'capped') console.debug('vitrine:settled');
    });
    document.addEventListener('vitrine-error', (event) => console.debug(`vitrine:failed ${/** @type {any} */ (event).detail.message}`));
  });
  /** @type {any[]} */
  const events = [];
  cdp.on('Tracing.dataCollected', (e) => events.push(...e.value));
  const traced = new Promise((resolve) => cdp.once('Tracing.tracingComplete', resolve));
  await cdp.send('Tracing.start', { categories: categories.join(','), transferMode: 'ReportEvents' });
  const settled = page.waitForEvent('console', {
    predicate: (m) => m.text() === 'vitrine:settled' || m.text().startsWith('vitrine:failed '),
    timeout: timeoutMs,
  });
  await page.goto(url, { waitUntil: 'commit' });
  const outcome = await settled.catch((/** @type {Error} */ error) => error);
  if (outcome instanceof Error || outcome.text() !== 'vitrine:settled') {
    const why = outcome instanceof Error ? `did not settle within ${timeoutMs / 1000} s` : outcome.text().slice('vitrine:failed '.length);
    const status = await page
      .evaluate(() => JSON.stringify(/** @type {any} */ (document.querySelector('vitrine-viewer'))?.viewer?.state ?? null))
      .catch(() => 'unknown');
    await cdp.send('Tracing.end').catch(() => {});
    await page.close();
    throw new Error(`the viewer at ${url} ${outcome instanceof Error ? why : `failed: ${why}`} (state ${status})`);
  }
  // Frames are drawn after they are issued (SwiftShader takes seconds for the
  // last level); wait for the GPU, so the next load does not start behind it.
  const drawnMs = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.renderer.finish());
  const state = await page.evaluate(() => /** @type {any} */ (document.querySelector('vitrine-viewer')).viewer.state);
  const collected = collect ? await collect(page) : undefined;
  await cdp.send('Tracing.end');
  await traced;
  await page.close();
  return { events, state, drawnMs, collected };
}
