// @ts-check
/**
 * What the renderer draws while the view moves. A scan's last level can
 * have millions of triangles: a desktop GPU draws them in a few
 * milliseconds, but a tablet's may take tens, and a CPU rasteriser (a
 * blocklisted GPU, a virtual machine; rasteriser.js) about a second on a
 * small machine, while sharing its cores with the decoders. Orbiting then
 * stutters at a frame a second. So the renderer keeps one coarser level
 * (the *stand-in*: the finest level received with at most a quarter of
 * the target's triangles, and at most {@link STAND_IN_TRIANGLES}) and draws
 * it in place of the level on screen while the view moves, where a frame
 * of that level took longer than {@link SLOW_FRAME_MS}; {@link REST_MS}
 * after the last move (longer where the level's frames take seconds:
 * {@link MAX_REST_MS}), the level is drawn again (after the release, when
 * a pointer holds the view: a drag that pauses is still a drag). Picking, measuring,
 * snapshots and the wireframe and relief views always use the level itself.
 *
 * Keeping the stand-in costs its normals and indices only (vertices are
 * shared by every level: vertex-store.js), a few MB at most. The cost of a
 * frame is timed with a fence (renderer.js), which resolves to an animation
 * frame: a fast GPU's frames read as one frame interval, well under the
 * threshold.
 */

/** Motion that has stopped this long is over: the next frame draws the level on screen. */
export const REST_MS = 250;

/**
 * The longest rest: where a frame of the level takes seconds (a CPU
 * rasteriser), the view must stay still for half a frame, up to this, before
 * one is started, since every move made while it is drawn waits for it. A
 * pause between wheel turns or key presses then keeps the stand-in.
 */
export const MAX_REST_MS = 1000;

/** A frame of the level that took longer than this (under 20 a second) makes motion use the stand-in. */
export const SLOW_FRAME_MS = 50;

/**
 * The most triangles a stand-in has. On SwiftShader at 800 × 600 on 2
 * cores, frames of a 200 k-triangle stand-in came about 145 ms apart, of a
 * 36 k one 80 ms (the rest of a frame's cost is fixed), against 1–3 s for
 * a 4.3 M-triangle level (BENCHMARKS.md, "Viewer").
 */
export const STAND_IN_TRIANGLES = 250_000;

/**
 * `auto`: the stand-in while moving where the level's frames are slow;
 * `full`: always the level (no stand-in kept); `coarse`: the stand-in
 * whenever the view moves (weak devices, tests).
 * @typedef {'auto' | 'full' | 'coarse'} MotionMode
 */

/** @param {unknown} value @returns {MotionMode | null} */
export function motionMode(value) {
  return value === 'auto' || value === 'full' || value === 'coarse' ? value : null;
}

export class MotionPolicy {
  /** performance.now() of the last change of view (−∞: never moved) */
  movedAt = -Infinity;
  /** The visitor holds the view (a pointer is down): moving until released, however still. */
  grabbed = false;
  /**
   * The last timed frame of a level: its triangles and milliseconds from
   * issue to the GPU done.
   * @type {{ triangles: number, ms: number } | null}
   */
  timed = null;

  /** @param {MotionMode} [mode] @param {number} [maxTriangles] */
  constructor(mode = 'auto', maxTriangles = STAND_IN_TRIANGLES) {
    this.mode = mode;
    this.maxTriangles = maxTriangles;
  }

  /**
   * The most triangles of a stand-in for levels heading for `capacity`
   * vertices (about two triangles each): a quarter of that, at most
   * `maxTriangles`.
   * @param {number} capacity
   */
  budget(capacity) {
    return Math.min(this.maxTriangles, Math.floor(capacity / 2));
  }

  /**
   * Whether a level leaving the screen becomes the stand-in (replacing
   * `standIn`, its triangles, or null): it is within the budget and finer.
   * @param {number} triangles
   * @param {number | null} standIn
   * @param {number} capacity vertices of the target level
   */
  keeps(triangles, standIn, capacity) {
    return this.mode !== 'full' && triangles <= this.budget(capacity) && (standIn === null || triangles > standIn);
  }

  /** The view changed at `now`. @param {number} now */
  moved(now) {
    this.movedAt = now;
  }

  /** @param {number} now */
  moving(now) {
    return this.grabbed || now - this.movedAt < this.restMs();
  }

  /** How long the view must stay still before the level is drawn: {@link REST_MS}, or half its last timed frame, at most {@link MAX_REST_MS}. */
  restMs() {
    return Math.min(MAX_REST_MS, Math.max(REST_MS, (this.timed?.ms ?? 0) / 2));
  }

  /**
   * A pointer went down on the view, or the last came up (`now`): a drag
   * that pauses is still a drag, so the level (a frame that may take
   * seconds) waits for the release and the rest after it.
   * @param {boolean} on
   * @param {number} now
   */
  grab(on, now) {
    if (this.grabbed && !on) this.movedAt = now;
    this.grabbed = on;
  }

  /**
   * A frame of a level of `triangles` took `ms` from issue to the GPU done.
   * @param {number} triangles
   * @param {number} ms
   */
  time(triangles, ms) {
    this.timed = { triangles, ms };
  }

  /**
   * Whether the next frame draws the stand-in (of `standIn` triangles, or
   * null) in place of the level on screen (`current` triangles): the view
   * is moving, the stand-in is at most half as heavy, and (`auto`) a frame
   * of a level no heavier than this one was slow. An untimed level is drawn
   * (and timed) once.
   * @param {number} now
   * @param {number} current
   * @param {number | null} standIn
   */
  drawsStandIn(now, current, standIn) {
    if (this.mode === 'full' || standIn === null || 2 * standIn > current || !this.moving(now)) return false;
    if (this.mode === 'coarse') return true;
    const timed = this.timed;
    return timed !== null && timed.triangles <= current && timed.ms > SLOW_FRAME_MS;
  }
}
