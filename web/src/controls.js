// @ts-check
/**
 * Mouse, touch and keyboard for the orbit camera, on Pointer Events so one
 * code path serves mouse, pen and fingers:
 * - one pointer (left button, one finger): rotate;
 * - right or middle button, or shift + left: pan;
 * - two fingers: pinch to zoom, move together to pan;
 * - wheel: zoom;
 * - keys, only while the canvas has focus (WCAG 2.1.4: no single-key
 *   shortcut acts elsewhere on the page): arrows rotate, shift + arrows
 *   pan, + / - zoom, R reset, W wireframe, F fullscreen, Enter or Space
 *   picks the point under the centre of the view (the measurement's
 *   crosshair);
 * - `nudge()`: one key step, for on-screen buttons that turn and zoom
 *   without a drag (WCAG 2.5.7).
 * While `locked` (the quality study's questions) all of it is ignored.
 */

const KEY_STEP_PX = 40;
const KEY_ZOOM = 1.15;
const WHEEL_ZOOM_PER_PX = 0.0015;

/**
 * @typedef {object} ControlActions
 * @property {() => import('./camera.js').OrbitCamera | null} camera
 * @property {() => void} changed the camera moved
 * @property {() => void} reset
 * @property {() => void} toggleWireframe
 * @property {() => void} toggleFullscreen
 * @property {(kind: Interaction) => void} [interacted] the visitor moved the camera (every move; the
 *   study's log coalesces them)
 * @property {(on: boolean) => void} [grabbed] a pointer went down on the view (true), or the last
 *   one came up (false): the renderer keeps drawing as if moving in between (motion.js)
 * @property {() => boolean} [pickCentre] Enter or Space: pick the point under the view's centre;
 *   false when nothing takes a pick now (the key then does what it does elsewhere)
 */

/** @typedef {'orbit' | 'pan' | 'zoom' | 'pinch' | 'key'} Interaction */
/** One step of the view, as a key or an on-screen button makes it. @typedef {'left' | 'right' | 'up' | 'down' | 'in' | 'out'} Nudge */

/** @type {Record<string, Nudge>} */
const KEY_NUDGES = { ArrowLeft: 'left', ArrowRight: 'right', ArrowUp: 'up', ArrowDown: 'down', '+': 'in', '=': 'in', '-': 'out' };

export class OrbitControls {
  /** @type {Map<number, { x: number, y: number }>} */
  #pointers = new Map();
  /** @type {{ distance: number, x: number, y: number } | null} */
  #pinch = null;
  #panning = false;
  /** Input is ignored (pointer, wheel, keys); a drag in progress ends. */
  #locked = false;

  get locked() {
    return this.#locked;
  }

  set locked(on) {
    this.#locked = on;
    if (on) {
      const held = this.#pointers.size > 0;
      this.#pointers.clear();
      this.#pinch = null;
      if (held) this.actions.grabbed?.(false);
    }
  }

  /**
   * @param {HTMLCanvasElement} canvas
   * @param {ControlActions} actions
   */
  constructor(canvas, actions) {
    this.canvas = canvas;
    this.actions = actions;
    canvas.style.touchAction = 'none';
    canvas.tabIndex = 0;
    canvas.addEventListener('pointerdown', (e) => this.#down(e));
    canvas.addEventListener('pointermove', (e) => this.#move(e));
    for (const type of ['pointerup', 'pointercancel', 'lostpointercapture']) {
      canvas.addEventListener(type, (e) => this.#up(/** @type {PointerEvent} */ (e)));
    }
    canvas.addEventListener('wheel', (e) => this.#wheel(e), { passive: false });
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('keydown', (e) => this.#key(e));
  }

  /** @param {PointerEvent} e */
  #down(e) {
    if (this.#locked) return;
    this.canvas.focus({ preventScroll: true });
    // Capture can fail for synthetic events; moves still arrive on the canvas.
    try {
      this.canvas.setPointerCapture(e.pointerId);
    } catch {}
    this.#pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    if (this.#pointers.size === 1) this.actions.grabbed?.(true);
    this.#panning = e.pointerType === 'mouse' && (e.button === 1 || e.button === 2 || e.shiftKey);
    this.#pinch = this.#pointers.size === 2 ? this.#twoFingers() : null;
    e.preventDefault();
  }

  /** @param {PointerEvent} e */
  #move(e) {
    const last = this.#pointers.get(e.pointerId);
    const camera = this.actions.camera();
    if (!last || !camera || this.#locked) return;
    /** @type {Interaction} */
    let kind = this.#panning ? 'pan' : 'orbit';
    const height = this.canvas.clientHeight || 1;
    if (this.#pointers.size === 1) {
      const dx = e.clientX - last.x;
      const dy = e.clientY - last.y;
      if (this.#panning) camera.pan(dx, dy, height);
      else camera.rotate(dx, dy, height);
    }
    this.#pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    if (this.#pointers.size === 2 && this.#pinch) {
      const now = this.#twoFingers();
      if (now.distance > 0 && this.#pinch.distance > 0) camera.zoom(this.#pinch.distance / now.distance);
      camera.pan(now.x - this.#pinch.x, now.y - this.#pinch.y, height);
      this.#pinch = now;
      kind = 'pinch';
    }
    this.actions.changed();
    this.actions.interacted?.(kind);
  }

  /** @param {PointerEvent} e */
  #up(e) {
    if (!this.#pointers.delete(e.pointerId)) return;
    // Lifting one of two fingers continues as a one-finger rotation from here.
    this.#pinch = this.#pointers.size === 2 ? this.#twoFingers() : null;
    if (this.#pointers.size === 0) this.actions.grabbed?.(false);
  }

  #twoFingers() {
    const [a, b] = [...this.#pointers.values()];
    return { distance: Math.hypot(a.x - b.x, a.y - b.y), x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 };
  }

  /** @param {WheelEvent} e */
  #wheel(e) {
    const camera = this.actions.camera();
    if (this.#locked) {
      e.preventDefault();
      return;
    }
    if (!camera) return;
    e.preventDefault();
    const pixels = e.deltaMode === 1 ? e.deltaY * 16 : e.deltaMode === 2 ? e.deltaY * 400 : e.deltaY;
    camera.zoom(Math.exp(pixels * WHEEL_ZOOM_PER_PX));
    this.actions.changed();
    this.actions.interacted?.('zoom');
  }

  /**
   * Turns, tilts or zooms the view by one key step; `pan` moves it instead of turning.
   * @param {Nudge} step
   * @param {{ pan?: boolean }} [options]
   * @returns {boolean} whether the camera moved (false while locked or before the model)
   */
  nudge(step, { pan = false } = {}) {
    const camera = this.actions.camera();
    if (!camera || this.#locked) return false;
    if (step === 'in' || step === 'out') {
      camera.zoom(step === 'in' ? 1 / KEY_ZOOM : KEY_ZOOM);
    } else {
      const [dx, dy] = { left: [-1, 0], right: [1, 0], up: [0, -1], down: [0, 1] }[step].map((s) => s * KEY_STEP_PX);
      const height = this.canvas.clientHeight || 1;
      if (pan) camera.pan(dx, dy, height);
      else camera.rotate(dx, dy, height);
    }
    this.actions.changed();
    this.actions.interacted?.('key');
    return true;
  }

  /** @param {KeyboardEvent} e */
  #key(e) {
    if (e.ctrlKey || e.metaKey || e.altKey || this.#locked) return;
    const nudge = KEY_NUDGES[e.key];
    if (nudge) {
      // Shift + an arrow pans; shift + "=" is "+" on most keyboards.
      const pan = e.shiftKey && e.key.startsWith('Arrow');
      if (this.nudge(nudge, { pan })) e.preventDefault();
    } else if (e.key === 'r' || e.key === 'R' || e.key === 'Home') {
      this.actions.reset();
      this.actions.changed();
      this.actions.interacted?.('key');
      e.preventDefault();
    } else if (e.key === 'w' || e.key === 'W') {
      this.actions.toggleWireframe();
      e.preventDefault();
    } else if (e.key === 'f' || e.key === 'F') {
      this.actions.toggleFullscreen();
      e.preventDefault();
    } else if ((e.key === 'Enter' || e.key === ' ') && this.actions.pickCentre?.()) {
      e.preventDefault();
    }
  }
}
