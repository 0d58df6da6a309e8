// @ts-check
/**
 * What the page and the splat worker (splat-worker.js) say to each other.
 */

/**
 * @typedef {{ type: 'points', module: WebAssembly.Module, baseUrl: string, batchUrls: string[], upTo: number,
 *     sharpThreshold?: number, headers?: Record<string, string> }
 *   | { type: 'extend', upTo: number }
 *   | { type: 'mesh', id: number, positions: Float32Array, indices: Uint32Array, colours: Uint8Array | null,
 *     sharpThreshold?: number }} SplatCommand
 */

/**
 * @typedef {{ type: 'splats', id: number | null, level: number, set: import('./splat-renderer.js').SplatSet, received: number, ms: number }
 *   | { type: 'error', kind: 'network' | 'decode', level: number, message: string }
 *   | { type: 'capped', level: number, status: number, reason: string | null, retryAfterS: number | null }
 *   | { type: 'done', level: number }} SplatMessage
 * `extend`: load up to a higher level (the cap rose); `mesh`: a mesh level's
 * splats, `sharpThreshold` (w_s, default 0.9) marking its sharp edges;
 * `capped`: the server
 * refused the level after `level` (the cap fell since the manifest was read).
 */

export {};
