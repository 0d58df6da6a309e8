// @ts-check
/**
 * Who made a scan and on what terms it may be reused: the manifest's
 * `rights` as the viewer's credit line, and as the text a snapshot carries.
 * A CC BY licence asks for the credit wherever the work goes, so the line
 * travels with the embed and the element, and with a saved PNG.
 */

/**
 * The manifest's `rights` (server/src/storage/curator/rights.rs); absent
 * from servers that predate it.
 * @typedef {{ id: string, name: string, url: string }} Licence
 * @typedef {{ credit: string | null, licence: Licence | null }} Rights
 */

/**
 * What the credit line shows: the credit text, and the licence's name with
 * its deed as a link (`href` null when the server sent no http(s) URL: the
 * name alone, never a `javascript:` link). Null when there is nothing to show.
 * @param {Partial<Rights> | null | undefined} rights
 * @returns {{ credit: string | null, licence: { name: string, href: string | null } | null } | null}
 */
export function creditLine(rights) {
  const credit = typeof rights?.credit === 'string' && rights.credit.trim() ? rights.credit.trim() : null;
  const l = rights?.licence;
  const licence = l && typeof l.name === 'string' && l.name ? { name: l.name, href: webUrl(l.url) } : null;
  return credit === null && licence === null ? null : { credit, licence };
}

/**
 * One line, as the server writes it into a GLB's `asset.copyright`
 * (`Rights::notice`): `Scan: Museo Nacional. Licence: CC BY 4.0 (https://…)`.
 * @param {Partial<Rights> | null | undefined} rights
 * @returns {string | null}
 */
export function copyrightNotice(rights) {
  const line = creditLine(rights);
  if (!line) return null;
  const l = rights?.licence;
  const licence = line.licence ? `Licence: ${line.licence.name}${l?.url ? ` (${l.url})` : ''}` : null;
  if (line.credit && licence) return `${line.credit}. ${licence}`;
  return line.credit ?? licence;
}

/**
 * The model's page on its Vitrine server, from the manifest's URL
 * (`…/api/models/{slug}` → `…/m/{slug}`): where a snapshot came from, also
 * when the element sits on a museum's own site.
 * @param {string} manifestUrl absolute
 * @returns {string | null}
 */
export function modelPageUrl(manifestUrl) {
  try {
    const url = new URL(manifestUrl);
    const match = url.pathname.match(/^(.*)\/api\/models\/([a-z0-9-]+)\/?$/);
    if (!match) return null;
    url.pathname = `${match[1]}/m/${match[2]}`;
    url.search = '';
    url.hash = '';
    return url.href;
  } catch {
    return null;
  }
}

/**
 * The text chunks of a snapshot (png-text.js): the title, the rights when
 * recorded, and the page it was taken from.
 * @param {{ title?: string, rights?: Partial<Rights> | null }} manifest
 * @param {string | null} pageUrl
 * @returns {Array<[string, string]>} keyword, text
 */
export function snapshotText(manifest, pageUrl) {
  /** @type {Array<[string, string]>} */
  const entries = [];
  if (manifest.title) entries.push(['Title', manifest.title]);
  const notice = copyrightNotice(manifest.rights);
  if (notice) entries.push(['Copyright', notice]);
  // `Source` is the camera in the PNG spec's list of keywords; the page goes in a comment.
  if (pageUrl) entries.push(['Comment', `Snapshot from ${pageUrl}`]);
  return entries;
}

/** @param {unknown} value @returns {string | null} the URL when it is http or https */
function webUrl(value) {
  if (typeof value !== 'string') return null;
  try {
    const url = new URL(value);
    return url.protocol === 'https:' || url.protocol === 'http:' ? url.href : null;
  } catch {
    return null;
  }
}
