// @ts-check
/**
 * Coming back when the service says to: a 503 (admission's `busy`, shedding,
 * a database restarting) or a load cap carries `Retry-After`, and the same
 * number in its JSON body's `retry_after_s` (the header is hidden from pages
 * of other origins unless exposed). Shared by the page (the manifest) and
 * the decode worker (payloads).
 */

/**
 * Seconds to wait, from the header or else the body; null when neither
 * gives a number of seconds (an HTTP date, nothing, `null`).
 * @param {Response} response
 * @param {any} body the answer's parsed JSON, if any
 * @returns {number | null}
 */
export function retryAfterSeconds(response, body) {
  const header = response.headers.get('retry-after');
  const value = header !== null ? Number(header) : typeof body?.retry_after_s === 'number' ? body.retry_after_s : NaN;
  return Number.isFinite(value) && value >= 0 ? value : null;
}

/**
 * Waits `seconds` plus 0–1 s of jitter, so that clients told the same time
 * do not all come back together; rejects with the signal's reason on abort.
 * @param {number} seconds
 * @param {AbortSignal} [signal]
 * @returns {Promise<void>}
 */
export function waitToRetry(seconds, signal) {
  return new Promise((resolve, reject) => {
    if (signal?.aborted) return reject(signal.reason);
    const timer = setTimeout(resolve, (seconds + Math.random()) * 1000);
    signal?.addEventListener(
      'abort',
      () => {
        clearTimeout(timer);
        reject(signal.reason);
      },
      { once: true },
    );
  });
}
