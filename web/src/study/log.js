// @ts-check
/**
 * The view-parameter log of a study session (thesis tb_parametro): state
 * changes, the visitor's interactions and the camera, each with the time
 * since the page's session start. Events queue here and leave in batches
 * (every few seconds, and at each answer), at most 200 events and well
 * under 64 KiB per request. The camera is sampled at most every
 * `cameraEveryMs` while it moves, and with every state change; a run of
 * moves of one kind is one interaction event.
 */

/** @typedef {import('./api.js').ViewEvent} ViewEvent */
/** @typedef {ViewEvent['state']} LogState */

export const MAX_EVENTS = 200;
/** Bytes of JSON per batch: the server refuses above 64 KiB. */
export const MAX_BYTES = 60_000;
const FLUSH_EVERY_MS = 5000;
const CAMERA_EVERY_MS = 200;
/** A pause this long ends an interaction: the next move is a new one. */
const GESTURE_GAP_MS = 600;

/**
 * The orbit camera as the log records it: eye, target and up in model
 * units, the vertical field of view in degrees, and the zoom (the home
 * distance over the current one: 1 at home, 2 twice as close).
 * @param {import('../camera.js').OrbitCamera} camera
 */
export function cameraRecord(camera) {
  const { eye, up } = camera.basis();
  const round = (/** @type {number[]} */ v) => v.map((x) => Number(x.toPrecision(6)));
  return {
    camera: { eye: round(eye), target: round(camera.state.target), up: round(up), fov: Number(((camera.fovY * 180) / Math.PI).toFixed(3)) },
    zoom: Number((camera.home.distance / camera.state.distance).toPrecision(6)),
  };
}

/**
 * Splits events into batches of at most MAX_EVENTS and MAX_BYTES of JSON.
 * @param {ViewEvent[]} events
 * @returns {ViewEvent[][]}
 */
export function batches(events) {
  /** @type {ViewEvent[][]} */
  const out = [];
  /** @type {ViewEvent[]} */
  let batch = [];
  let bytes = 20;
  for (const event of events) {
    const size = JSON.stringify(event).length + 1;
    if (batch.length > 0 && (batch.length >= MAX_EVENTS || bytes + size > MAX_BYTES)) {
      out.push(batch);
      batch = [];
      bytes = 20;
    }
    batch.push(event);
    bytes += size;
  }
  if (batch.length > 0) out.push(batch);
  return out;
}

export class ViewLog {
  /** @type {ViewEvent[]} */
  #queue = [];
  /** Everything recorded (tests read it). @type {ViewEvent[]} */
  all = [];
  step = 0;
  /** @type {LogState} */
  state = 'info';
  #lastCamera = -Infinity;
  /** @type {{ kind: string, at: number } | null} */
  #gesture = null;
  /** @type {ReturnType<typeof setInterval> | null} */
  #timer = null;
  /** @type {Promise<void>} */
  #sending = Promise.resolve();

  /**
   * @param {object} options
   * @param {(events: ViewEvent[]) => Promise<unknown>} options.send one batch
   * @param {() => number} options.now clock ms (performance.now())
   * @param {number} options.origin the session's start on that clock
   * @param {() => import('../camera.js').OrbitCamera | null} options.camera
   * @param {number} [options.cameraEveryMs]
   */
  constructor({ send, now, origin, camera, cameraEveryMs = CAMERA_EVERY_MS }) {
    this.send = send;
    this.now = now;
    this.origin = origin;
    this.camera = camera;
    this.cameraEveryMs = cameraEveryMs;
  }

  /** Sends a batch every few seconds until stop(). */
  start() {
    this.#timer ??= setInterval(() => void this.flush(), FLUSH_EVERY_MS);
  }

  stop() {
    if (this.#timer !== null) clearInterval(this.#timer);
    this.#timer = null;
  }

  /**
   * A state began (at `at` on the clock, default now); the camera goes with it.
   * @param {number} step
   * @param {LogState} state
   * @param {number} [at]
   */
  enter(step, state, at) {
    this.step = step;
    this.state = state;
    this.#push({ kind: 'state', ...this.#cameraFields() }, at);
    this.#lastCamera = this.now();
  }

  /**
   * The visitor moved the camera.
   * @param {import('../controls.js').Interaction} kind
   */
  interaction(kind) {
    const now = this.now();
    const gesture = this.#gesture;
    if (!gesture || gesture.kind !== kind || now - gesture.at > GESTURE_GAP_MS) {
      this.#push({ kind: 'interaction', interaction: kind, ...this.#cameraFields() });
      this.#lastCamera = now;
    } else if (now - this.#lastCamera >= this.cameraEveryMs) {
      this.#push({ kind: 'camera', interaction: kind, ...this.#cameraFields() });
      this.#lastCamera = now;
    }
    this.#gesture = { kind, at: now };
  }

  /**
   * Sends what is queued (in order, one request at a time); a batch that
   * fails is kept and tried again with the next flush.
   * @returns {Promise<void>}
   */
  flush() {
    this.#sending = this.#sending.then(async () => {
      const events = this.#queue;
      this.#queue = [];
      const parts = batches(events);
      for (let i = 0; i < parts.length; i++) {
        try {
          await this.send(parts[i]);
        } catch {
          this.#queue = [...parts.slice(i).flat(), ...this.#queue];
          return;
        }
      }
    });
    return this.#sending;
  }

  #cameraFields() {
    const camera = this.camera();
    return camera ? cameraRecord(camera) : {};
  }

  /**
   * @param {Pick<ViewEvent, 'kind'> & Partial<ViewEvent>} fields
   * @param {number} [at]
   */
  #push(fields, at) {
    /** @type {ViewEvent} */
    const event = {
      at_ms: Number(((at ?? this.now()) - this.origin).toFixed(1)),
      step: this.step,
      state: this.state,
      ...fields,
    };
    this.#queue.push(event);
    this.all.push(event);
  }
}
