// @ts-check
/**
 * The curators' API as the /admin page calls it: the token from
 * sessionStorage, sent only as `Authorization: Bearer` (no cookies).
 */

const TOKEN_KEY = 'vitrine.curatorToken';

/** @returns {string | null} */
export function savedToken() {
  return sessionStorage.getItem(TOKEN_KEY);
}

/** @param {string | null} token */
export function saveToken(token) {
  if (token) sessionStorage.setItem(TOKEN_KEY, token);
  else sessionStorage.removeItem(TOKEN_KEY);
}

/**
 * @typedef {{ id: number, slug: string, title: string, source_name: string,
 *   state: 'queued' | 'running' | 'done' | 'failed', progress: number, stage: string,
 *   error: string | null, model_version: number | null, model_url: string | null,
 *   created_at: number, updated_at: number }} Job
 * @typedef {{ version: number, title: string, status: string, policy: string,
 *   good_enough_level: number | null, levels: number, created_at: number,
 *   credit?: string | null, licence?: string | null }} Version
 * @typedef {import('../rights.js').Licence} Licence
 * @typedef {{ status?: string, good_enough_level?: number | null,
 *   credit?: string | null, licence?: string | null }} VersionChange
 */

/** An answer that is not 2xx, with the server's message. */
export class ApiError extends Error {
  /** @param {number} status @param {string} message */
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

/**
 * @param {string} path
 * @param {RequestInit} [init]
 * @returns {Promise<any>}
 */
export async function call(path, init = {}) {
  const headers = new Headers(init.headers);
  const token = savedToken();
  if (token) headers.set('Authorization', `Bearer ${token}`);
  const response = await fetch(path, { ...init, headers, cache: 'no-store', credentials: 'omit' });
  if (!response.ok) {
    let message = `the server answered ${response.status}`;
    try {
      const body = await response.json();
      // `{ error: code, message }`, or `{ error: { message } }`.
      if (body && typeof body.message === 'string') message = body.message;
      else if (typeof body?.error?.message === 'string') message = body.error.message;
    } catch {
      // Not JSON: keep the status.
    }
    throw new ApiError(response.status, message);
  }
  if (response.status === 204) return null;
  return response.json();
}

/** @returns {Promise<Job[]>} */
export async function jobs() {
  return (await call('/api/jobs')).jobs;
}

/** @param {FormData} form @returns {Promise<{ job: number, status_url: string }>} */
export function upload(form) {
  return call('/api/models', { method: 'POST', body: form });
}

/** @returns {Promise<Array<{ slug: string, title: string }>>} */
export async function models() {
  return (await call('/api/models')).models;
}

/** @param {string} slug @returns {Promise<Version[]>} */
export async function versions(slug) {
  return (await call(`/api/admin/models/${slug}/versions`)).versions;
}

/** The licences and rights statements a version may name (public). @returns {Promise<Licence[]>} */
export async function licences() {
  return (await call('/api/licences')).licences;
}

/**
 * @param {string} slug
 * @param {number} version
 * @param {VersionChange} change (credit or licence `""`: clear it)
 * @returns {Promise<Version>}
 */
export function changeVersion(slug, version, change) {
  return call(`/api/admin/models/${slug}/versions/${version}`, {
    method: 'PUT',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(change),
  });
}

/**
 * A version's title, description and credit: their language as given, and
 * their translations by BCP 47 tag (a field left out falls back to the
 * default text).
 * @typedef {import('../content-language.js').ContentTranslation} Translation
 * @typedef {{ language: string | null, title: string, description: string, credit: string | null,
 *   translations: Record<string, Translation> }} VersionTexts
 * @typedef {{ language: string | null, translations: Record<string, Translation> }} VersionTextsChange
 */

/** @param {string} slug @param {number} version @returns {Promise<VersionTexts>} */
export function texts(slug, version) {
  return call(`/api/admin/models/${slug}/versions/${version}/texts`);
}

/**
 * Replaces the language of the default texts and every translation of the version.
 * @param {string} slug @param {number} version @param {VersionTextsChange} change
 * @returns {Promise<VersionTexts>}
 */
export function saveTexts(slug, version, change) {
  return call(`/api/admin/models/${slug}/versions/${version}/texts`, {
    method: 'PUT',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(change),
  });
}

/**
 * @typedef {{ view: string, title: Record<string, string>, text: Record<string, string>, html?: Record<string, string> }} TourStep
 * @typedef {{ id: number, version: number, title: Record<string, string>, steps: TourStep[] }} Tour
 * @typedef {{ title: Record<string, string>, steps: TourStep[], version?: number }} TourInput
 */

/** Every tour of the model, of every version. @param {string} slug @returns {Promise<Tour[]>} */
export function tours(slug) {
  return call(`/api/admin/models/${slug}/tours`);
}

/**
 * Creates (`id` null) or replaces a tour.
 * @param {string} slug @param {number | null} id @param {TourInput} tour
 * @returns {Promise<Tour>}
 */
export function saveTour(slug, id, tour) {
  return call(id === null ? `/api/admin/models/${slug}/tours` : `/api/admin/models/${slug}/tours/${id}`, {
    method: id === null ? 'POST' : 'PUT',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(tour),
  });
}

/** @param {string} slug @param {number} id */
export function deleteTour(slug, id) {
  return call(`/api/admin/models/${slug}/tours/${id}`, { method: 'DELETE' });
}
