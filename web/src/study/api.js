// @ts-check
/**
 * The study's HTTP calls (server: `/api/study/…`). Every call but the
 * public results carries the invitation as `Authorization: Bearer …`.
 * Errors come back as {@link StudyError} with the server's status and code.
 */

/**
 * `GET /api/study/{slug}`.
 * @typedef {object} StudyInfo
 * @property {string} slug
 * @property {string} title
 * @property {'open'} state
 * @property {number} seconds T
 * @property {number} step_count
 * @property {number} last_level
 * @property {'valid' | 'started' | 'finished'} invitation
 */

/**
 * A session's plan (`POST …/session`, `GET …/session`).
 * @typedef {object} StudyPlan
 * @property {string} slug
 * @property {number} version
 * @property {string} participant pseudonym
 * @property {number} seconds T
 * @property {number} last_level
 * @property {import('./machine.js').PlanStep[]} steps
 * @property {number[]} answered steps already answered
 * @property {number | null} next_step
 * @property {boolean} finished
 */

/** @typedef {'none' | 'a-little' | 'improved' | 'greatly'} Improvement */

/**
 * @typedef {object} Answer
 * @property {Improvement} improvement Q1
 * @property {boolean} sufficient Q2
 * @property {[number, number]} shown_ms how long m_a and m_b were shown
 */

/**
 * One event of the view log.
 * @typedef {object} ViewEvent
 * @property {number} at_ms since the page's session start
 * @property {number} step 0 outside the steps
 * @property {'pre' | 'transition' | 'post' | 'answer' | 'info' | 'practice' | 'original'} state
 * @property {'camera' | 'state' | 'interaction'} kind
 * @property {{ eye: number[], target: number[], up: number[], fov: number }} [camera]
 * @property {number} [zoom]
 * @property {import('../controls.js').Interaction} [interaction]
 */

/**
 * @typedef {object} StudyResults
 * @property {number} valid_sessions
 * @property {Array<{ level: number, answers: number, sufficient: number }>} levels
 */

export class StudyError extends Error {
  /**
   * @param {number} status
   * @param {string} code
   * @param {string} message
   */
  constructor(status, code, message) {
    super(message);
    this.status = status;
    this.code = code;
  }
}

export class StudyApi {
  /**
   * @param {string} slug
   * @param {string} invitation
   * @param {{ base?: string, fetch?: typeof fetch }} [options]
   */
  constructor(slug, invitation, options = {}) {
    this.slug = slug;
    this.invitation = invitation;
    this.base = `${options.base ?? ''}/api/study/${encodeURIComponent(slug)}`;
    this.fetchImpl = options.fetch ?? ((input, init) => fetch(input, init));
  }

  /** @returns {Promise<StudyInfo>} */
  info() {
    return this.#call('GET', '');
  }

  /**
   * Starts (or resumes) the session: only called once consent is given.
   * @param {{ device: 'desktop' | 'tablet' | 'phone', viewport: [number, number], pixel_ratio: number }} client
   * @returns {Promise<StudyPlan>}
   */
  start(client) {
    return this.#call('POST', '/session', { consent: true, ...client });
  }

  /** @returns {Promise<StudyPlan>} */
  plan() {
    return this.#call('GET', '/session');
  }

  /**
   * @param {number} step
   * @param {Answer} answer
   */
  answer(step, answer) {
    return this.#call('PUT', `/session/answers/${step}`, answer);
  }

  /** @param {ViewEvent[]} events at most 200, under 64 KiB of JSON (log.js batches them) */
  views(events) {
    return this.#call('POST', '/session/views', { events }, { keepalive: true });
  }

  /** @returns {Promise<{ good_level: number | null }>} */
  finish() {
    return this.#call('POST', '/session/finish');
  }

  /**
   * @param {string} method
   * @param {string} path
   * @param {unknown} [body]
   * @param {{ keepalive?: boolean }} [options] keepalive: the request outlives the page (the log's last batch)
   */
  async #call(method, path, body, options = {}) {
    /** @type {Record<string, string>} */
    const headers = { authorization: `Bearer ${this.invitation}` };
    if (body !== undefined) headers['content-type'] = 'application/json';
    let response;
    try {
      response = await this.fetchImpl(this.base + path, {
        method,
        headers,
        body: body === undefined ? undefined : JSON.stringify(body),
        cache: 'no-store',
        keepalive: options.keepalive,
      });
    } catch (error) {
      throw new StudyError(0, 'network', `could not reach the server (${error instanceof Error ? error.message : error})`);
    }
    if (response.status === 204) return null;
    const data = await response.json().catch(() => null);
    if (!response.ok) {
      throw new StudyError(response.status, data?.error ?? 'http', data?.message ?? `the server answered ${response.status}`);
    }
    return data;
  }
}

/**
 * The public per-level share of "sufficient" answers; null when the model has no study with answers (404).
 * @param {string} slug
 * @param {typeof fetch} [fetchImpl]
 * @returns {Promise<StudyResults | null>}
 */
export async function fetchResults(slug, fetchImpl = (input, init) => fetch(input, init)) {
  const response = await fetchImpl(`/api/study/${encodeURIComponent(slug)}/results`, { cache: 'no-store' });
  if (response.status === 404) return null;
  if (!response.ok) throw new Error(`the server answered ${response.status} for the study results`);
  return response.json();
}
