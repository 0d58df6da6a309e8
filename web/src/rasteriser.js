// @ts-check
/**
 * Whether WebGL draws on a GPU or on the CPU. Browsers fall back to a
 * software rasteriser (Chrome's SwiftShader, Mesa's llvmpipe, Windows' Basic
 * Render Driver) where the GPU is blocklisted, in virtual machines and remote
 * desktops, and in headless test browsers. There a frame of a multi-million-
 * triangle scan costs seconds of CPU, shared with the decoders, and
 * multisampling multiplies it: on a 2-core machine, 4× MSAA kept SwiftShader
 * busy for 6–7 s before the last level of a 2 M-vertex scan could be drawn,
 * against 0.7–1.4 s without it (BENCHMARKS.md, "Charts"). So the renderer
 * asks for antialiasing only on a GPU.
 */

/** Renderer strings of the CPU rasterisers browsers fall back to. */
const SOFTWARE = /swiftshader|llvmpipe|softpipe|software|basic render driver|lavapipe/i;

/**
 * @param {string} renderer the WebGL renderer string (unmasked where the browser tells it)
 * @returns {boolean}
 */
export function isSoftwareRasteriser(renderer) {
  return SOFTWARE.test(renderer);
}

/**
 * The renderer string of a throwaway 1×1 WebGL2 context (freed at once), or
 * null where there is no WebGL2. Antialiasing is a context attribute, fixed
 * when the context is made, so the real canvas's context cannot ask itself.
 * @returns {string | null}
 */
export function probeRenderer() {
  try {
    const canvas = typeof OffscreenCanvas === 'function' ? new OffscreenCanvas(1, 1) : document.createElement('canvas');
    const gl = /** @type {WebGL2RenderingContext | null} */ (canvas.getContext('webgl2'));
    if (!gl) return null;
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER) ?? '');
    // Free it now rather than at garbage collection: the real context comes next.
    gl.getExtension('WEBGL_lose_context')?.loseContext();
    return name;
  } catch {
    return null;
  }
}
