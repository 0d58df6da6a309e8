// @ts-check
/**
 * One level's payload from the service, as every decode loop fetches it: a
 * 503 that says when to come back (shedding under load, a database
 * restarting) is waited out, with 0–1 s of jitter, a few times; a level
 * cap answer (403/429 with `"error": "level_capped"`) is a result, not an
 * error; anything else not OK is a {@link NetworkError}. Shared by the mesh
 * decode worker (reconstruction.js) and the splat worker (splats/).
 */

import { retryAfterSeconds, waitToRetry } from './retry.js';

/** Thrown for transport failures and unexpected HTTP answers. */
export class NetworkError extends Error {}

/** How many times one payload waits out a 503 with Retry-After. */
const UNAVAILABLE_RETRIES = 5;

/** @typedef {{ status: number, reason: string | null, retryAfterS: number | null }} Refusal */
/** @typedef {{ bytes: Uint8Array } | { capped: Refusal }} Fetched */

/**
 * @typedef {object} PayloadOptions
 * @property {string} what the payload in messages (`base mesh`, `batch 3`)
 * @property {Record<string, string>} [headers]
 * @property {AbortSignal} [signal]
 * @property {typeof fetch} [fetchImpl]
 * @property {(response: Response) => Promise<Uint8Array>} [read] reads the body (default: all of it at once)
 */

/**
 * @param {string} url
 * @param {PayloadOptions} options
 * @returns {Promise<Fetched>}
 */
export async function fetchPayload(url, { what, headers, signal, fetchImpl = fetch, read = readAll }) {
  /** @type {Response} */
  let response;
  for (let tries = 0; ; tries++) {
    try {
      response = await fetchImpl(url, { headers, signal });
    } catch (error) {
      throw new NetworkError(`could not fetch the ${what}: ${error instanceof Error ? error.message : String(error)}`);
    }
    if (response.status !== 503 || tries >= UNAVAILABLE_RETRIES) break;
    const wait = retryAfterSeconds(response, await response.json().catch(() => null));
    if (wait === null) break;
    await waitToRetry(Math.min(wait, 60), signal);
  }
  if (response.status === 403 || response.status === 429) {
    const body = await response.json().catch(() => ({}));
    if (body && body.error === 'level_capped') {
      const retryAfterS = retryAfterSeconds(response, body);
      return { capped: { status: response.status, reason: body.reason ?? null, retryAfterS } };
    }
  }
  if (!response.ok) throw new NetworkError(`the server answered ${response.status} for the ${what}`);
  try {
    return { bytes: await read(response) };
  } catch (error) {
    throw new NetworkError(`the ${what} was cut off: ${error instanceof Error ? error.message : String(error)}`);
  }
}

/** @param {Response} response */
async function readAll(response) {
  return new Uint8Array(await response.arrayBuffer());
}
