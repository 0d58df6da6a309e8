// Builds web/dist from web/src and the WebAssembly decoder:
//   node build.mjs            (expects the wasm to be built, see README)
//   VITRINE_WASM=path node build.mjs
// esbuild bundles six entries: app.js (the pages), vitrine.js (the
// <vitrine-viewer> element for other sites), worker.js (the decoder),
// chart-worker.js (its helpers for a charted stream), render-worker.js
// (WebGL on an OffscreenCanvas), splat-worker.js (point streams and splat
// preprocessing) — the last four classic workers, so
// another origin can start them from blob URLs.
import { build } from 'esbuild';
import { copyFileSync, existsSync, mkdirSync, rmSync, statSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const web = dirname(fileURLToPath(import.meta.url));
const src = join(web, 'src');
const dist = join(web, 'dist');
const wasm =
  process.env.VITRINE_WASM ?? join(web, '..', 'target', 'wasm32-unknown-unknown', 'wasm', 'vitrine_wasm.wasm');

if (!existsSync(wasm)) {
  console.error(`missing ${wasm}: run cargo build -p vitrine-wasm --target wasm32-unknown-unknown --profile wasm`);
  process.exit(1);
}
rmSync(dist, { recursive: true, force: true });
mkdirSync(dist, { recursive: true });

/** @type {import('esbuild').BuildOptions} */
const common = { bundle: true, minify: true, sourcemap: true, target: ['chrome111', 'firefox113', 'safari16.4'], logLevel: 'warning' };
await build({ ...common, entryPoints: { app: join(src, 'app.js'), vitrine: join(src, 'element.js') }, format: 'esm', outdir: dist });
await build({
  ...common,
  entryPoints: {
    worker: join(src, 'worker.js'),
    'chart-worker': join(src, 'chart-worker.js'),
    'render-worker': join(src, 'render-worker.js'),
    'splat-worker': join(src, 'splats', 'splat-worker.js'),
  },
  format: 'iife',
  outdir: dist,
});
for (const file of ['index.html', 'style.css']) copyFileSync(join(src, file), join(dist, file));
copyFileSync(wasm, join(dist, 'vitrine_wasm.wasm'));

for (const file of ['app.js', 'vitrine.js', 'worker.js', 'chart-worker.js', 'render-worker.js', 'splat-worker.js', 'vitrine_wasm.wasm']) {
  console.log(`dist/${file.padEnd(18)} ${(statSync(join(dist, file)).size / 1024).toFixed(1)} KB`);
}
