// @ts-check
/**
 * Headless Chromium (Debian's `chromium`) driven by playwright-core, with
 * WebGL2 on SwiftShader: the same flags for the end-to-end tests, the
 * benchmarks and the screenshot script.
 */
import { chromium } from 'playwright-core';
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';

export const CHROMIUM_ARGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader',
];

/**
 * A browser context in a fresh profile directory, removed on close.
 * `gpuCompositing` drops `--disable-gpu`, so the compositor also runs on
 * SwiftShader instead of in software: then a WebGL frame reaches the screen
 * as a texture, as on a real tablet, instead of being read back to the
 * renderer's main thread at every commit.
 * @param {{ width?: number, height?: number, deviceScaleFactor?: number, hasTouch?: boolean, gpuCompositing?: boolean }} [options]
 */
export async function launch(options = {}) {
  if (!existsSync(CHROMIUM)) throw new Error(`${CHROMIUM} is missing: apt-get install -y chromium`);
  const profile = mkdtempSync(join(tmpdir(), 'vitrine-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: options.gpuCompositing ? CHROMIUM_ARGS.filter((a) => a !== '--disable-gpu') : CHROMIUM_ARGS,
    viewport: { width: options.width ?? 800, height: options.height ?? 600 },
    deviceScaleFactor: options.deviceScaleFactor ?? 1,
    hasTouch: options.hasTouch ?? false,
  });
  const close = async () => {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  };
  return { context, close };
}

/**
 * Waits until the `<vitrine-viewer>` notice reads `pattern` (fails after
 * 10 s). The viewer's state and its notice are not updated in one step, so
 * a single read right after a state change can fall between them.
 * @param {import('playwright-core').Page} page
 * @param {RegExp} pattern
 */
export function noticeMatching(page, pattern) {
  return page.waitForFunction(
    ([source, flags]) => {
      const e = /** @type {HTMLElement | null} */ (document.querySelector('vitrine-viewer')?.shadowRoot?.querySelector('.notice') ?? null);
      return e !== null && new RegExp(source, flags).test(e.innerText);
    },
    [pattern.source, pattern.flags],
    { timeout: 10_000, polling: 50 },
  );
}
