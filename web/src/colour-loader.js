// @ts-check
/**
 * Progressive colour for a model in `ccc` mode (thesis §5,
 * ../codec/colour/CCC.md): after the base mesh's first frame, the cell
 * texture (PNG, decoded by png.js so every byte reaches the texture
 * exactly) and the low-resolution colour texture (JPEG) in parallel, then
 * the full-resolution colour texture, which replaces the low one when it
 * arrives. A failure leaves the model in per-vertex colour or clay with a
 * notice, never an error overlay. The viewer (viewer.js) says when to start;
 * this file fetches, decodes, checks and hands the textures to the renderer.
 */

import { checkParameters } from './ccc.js';
import { decodePng } from './png.js';

/** @typedef {import('./viewer.js').Manifest} Manifest */
/** @typedef {import('./viewer.js').ViewerState} ViewerState */

/**
 * What the loader reads from and writes to its viewer. Read when needed,
 * not kept: a re-check of the cap replaces the manifest, a retry may open
 * the renderer late.
 * @typedef {object} ColourHost
 * @property {() => Manifest | null} manifest
 * @property {() => import('./render-host.js').RenderHost | null} renderer
 * @property {(path: string) => string} url an API path as an absolute URL with the page's query
 * @property {(patch: Partial<ViewerState>) => void} set updates the viewer's state (colour, colourError, colourAtMs)
 */

/** @param {unknown} error */
function describe(error) {
  return error instanceof Error ? error.message : String(error);
}

export class ColourLoader {
  /** The cell texture URL whose mapping is loaded or loading (kept across retries). */
  #source = /** @type {string | null} */ (null);

  /** @param {ColourHost} host */
  constructor(host) {
    this.host = host;
  }

  /**
   * A (new) manifest: a model not in `ccc` mode drops any mapping and says
   * what colours it (per vertex, or clay); one in `ccc` mode whose cell
   * texture is not already loaded or loading is `loading` until load() has
   * its textures.
   * @param {Manifest} manifest
   */
  begin(manifest) {
    const mode = manifest.colour?.mode ?? (manifest.has_colour ? 'vertex' : 'none');
    if (mode !== 'ccc') {
      this.#source = null;
      this.host.renderer()?.setColourMapping(null);
      this.host.set({ colour: mode, colourError: null });
    } else if (this.#source !== /** @type {any} */ (manifest.colour).cell_texture.url) {
      this.host.set({ colour: 'loading', colourError: null });
    }
  }

  /**
   * Loads the textures of the viewer's manifest, once per cell texture URL:
   * nothing to do without a `ccc` manifest or a renderer, or when they are
   * already loaded or loading. Never rejects.
   */
  async load() {
    const colour = this.host.manifest()?.colour;
    const renderer = this.host.renderer();
    if (!colour || colour.mode !== 'ccc' || !renderer) return;
    if (this.#source === colour.cell_texture.url) return;
    this.#source = colour.cell_texture.url;
    const source = this.#source;
    const current = () => this.#source === source;
    this.host.set({ colourAtMs: { requested: performance.now() }, colour: 'loading', colourError: null });
    try {
      const [cells, low] = await Promise.all([
        this.#fetchBytes(colour.cell_texture.url).then(decodePng),
        this.#fetchImage(colour.colour_texture_low.url),
      ]);
      if (!current()) return;
      checkParameters(colour.parameters, cells);
      const max = renderer.maxTextureSize;
      if (Math.max(cells.width, cells.height, low.width, low.height) > max) {
        throw new Error(`the colour textures are larger than this GPU's limit (${max} texels)`);
      }
      renderer.setColourMapping({ parameters: colour.parameters, cells });
      renderer.setColourAtlas(low, 'low');
      this.host.set({ colour: 'low' });
    } catch (error) {
      if (!current()) return;
      this.#source = null;
      const mode = this.host.manifest()?.has_colour ? 'vertex' : 'none';
      this.host.set({ colour: mode, colourError: `the colour texture could not be loaded: ${describe(error)}` });
      return;
    }
    try {
      const full = await this.#fetchImage(colour.colour_texture.url);
      if (!current()) return;
      if (Math.max(full.width, full.height) > renderer.maxTextureSize) {
        throw new Error(`the full-resolution colour texture is larger than this GPU's limit (${renderer.maxTextureSize} texels)`);
      }
      renderer.setColourAtlas(full, 'full');
      this.host.set({ colour: 'full' });
    } catch (error) {
      if (current()) this.host.set({ colourError: `showing low-resolution colour: ${describe(error)}` });
    }
  }

  /** @param {string} path */
  async #fetchBytes(path) {
    let response;
    try {
      response = await fetch(this.host.url(path));
    } catch (error) {
      throw new Error(`could not reach the server (${describe(error)})`);
    }
    if (!response.ok) throw new Error(`the server answered ${response.status}`);
    return new Uint8Array(await response.arrayBuffer());
  }

  /**
   * A colour texture decoded off the main thread, bytes as stored (no
   * colour-space conversion).
   * @param {string} path
   */
  async #fetchImage(path) {
    const bytes = await this.#fetchBytes(path);
    return createImageBitmap(new Blob([bytes], { type: 'image/jpeg' }), {
      colorSpaceConversion: 'none',
      premultiplyAlpha: 'none',
      imageOrientation: 'from-image',
    });
  }
}
