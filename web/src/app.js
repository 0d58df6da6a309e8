// @ts-check
/**
 * The pages `vitrine serve` maps to one index.html: the gallery at `/`, a
 * model page at `/m/{slug}` (viewer, description, embed snippets) and the
 * bare viewer at `/embed/{slug}` for iframes, and the quality study at
 * `/study/{slug}?invitation=…` (study/page.js). `?device=`, `?token=`,
 * `?level=`, `?offscreen=off`, `?decoders=`, `?antialias=` and `?motion=` on a page's URL are passed to the viewer.
 */

import './element.js';
import { fetchResults } from './study/api.js';
import { StudyPage } from './study/page.js';

const main = /** @type {HTMLElement} */ (document.getElementById('app'));
const params = new URLSearchParams(location.search);
const route = location.pathname.match(/^\/(m|embed|study)\/([a-z0-9-]+)\/?$/);

if (!route) void (location.pathname === '/admin' ? import('./admin/page.js').then((admin) => admin.start(main)) : gallery());
else if (route[1] === 'm') modelPage(route[2]);
else if (route[1] === 'study') void new StudyPage(main, route[2], params).start();
else embedPage(route[2]);

/**
 * @param {string} tag
 * @param {Record<string, string>} [attributes]
 * @param {Array<Node | string>} [children]
 */
function el(tag, attributes = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  node.append(...children);
  return node;
}

/** @param {string} slug */
function viewerElement(slug) {
  const viewer = el('vitrine-viewer', { src: `/api/models/${slug}` });
  for (const key of ['device', 'token', 'level', 'offscreen', 'decoders', 'antialias', 'motion']) {
    const value = params.get(key);
    if (value !== null) viewer.setAttribute(key, value);
  }
  return viewer;
}

async function gallery() {
  document.body.classList.add('gallery');
  const list = el('ul', { class: 'models' });
  main.replaceChildren(
    el('header', {}, [
      el('h1', {}, ['Vitrine']),
      el('p', {}, ['3D scans from the collection: each appears at once in coarse form and sharpens as you look.']),
    ]),
    list,
  );
  try {
    const response = await fetch('/api/models', { cache: 'no-store' });
    if (!response.ok) throw new Error(`the server answered ${response.status}`);
    /** @type {{ models: Array<{ slug: string, title: string, levels: number, page_url: string, thumbnail?: string | null }> }} */
    const { models } = await response.json();
    if (models.length === 0) list.append(el('li', {}, ['No models yet: `vitrine ingest` adds one.']));
    for (const m of models) {
      const link = el('a', { href: m.page_url }, [thumbnail(m), el('strong', {}, [m.title]), el('small', {}, [`${m.levels} levels`])]);
      list.append(el('li', {}, [link]));
    }
  } catch (error) {
    list.append(el('li', { class: 'error', role: 'alert' }, [`Could not load the models: ${error}`]));
  }
}

/**
 * The model's picture (rendered at ingest), lazily loaded in a box of
 * fixed aspect so the grid does not move as pictures arrive; a neutral
 * placeholder when the server has none (or an older server, without the field).
 * @param {{ title: string, thumbnail?: string | null }} m
 */
function thumbnail(m) {
  const box = el('span', { class: 'thumb' });
  if (typeof m.thumbnail === 'string' && m.thumbnail) {
    const img = el('img', { src: m.thumbnail, alt: `${m.title}: preview`, loading: 'lazy', decoding: 'async', width: '320', height: '240' });
    img.addEventListener('error', () => img.replaceWith(el('span', { class: 'thumb-none', 'aria-hidden': 'true' })));
    box.append(img);
  } else {
    box.classList.add('thumb-none');
    box.setAttribute('aria-hidden', 'true');
  }
  return box;
}

/** @param {string} slug */
function modelPage(slug) {
  document.body.classList.add('model');
  const viewer = viewerElement(slug);
  viewer.setAttribute('chrome', 'full');
  const origin = location.origin;
  const iframe =
    `<iframe src="${origin}/embed/${slug}" width="800" height="600" style="border:0" ` +
    `allow="fullscreen" allowfullscreen title="3D model"></iframe>`;
  const element =
    `<script type="module" src="${origin}/vitrine.js"></script>\n` +
    `<vitrine-viewer src="${origin}/m/${slug}" style="width:800px;height:600px"></vitrine-viewer>`;
  main.replaceChildren(
    el('header', {}, [el('a', { href: '/' }, ['← All models'])]),
    viewer,
    el('section', { class: 'embed' }, [
      el('h2', {}, ['Embed this model']),
      snippet('An iframe, for any site:', iframe),
      snippet('Or the viewer element, styled by your page:', element),
    ]),
  );
  // The quality study's answers, when the model has a study (404: none, nothing shown).
  void fetchResults(slug)
    .then((results) => {
      if (results) /** @type {any} */ (viewer).viewer?.ui.setStudy(results.levels);
    })
    .catch(() => {});
  viewer.addEventListener('vitrine-level', () => {
    const title = /** @type {any} */ (viewer).viewer?.manifest?.title;
    // The site's name as the server states it (`--site-name`).
    const site = document.querySelector('meta[name="application-name"]')?.getAttribute('content') || 'Vitrine';
    if (title) document.title = `${title} · ${site}`;
  });
}

/** @param {string} slug */
function embedPage(slug) {
  document.body.classList.add('embed');
  const viewer = viewerElement(slug);
  viewer.setAttribute('chrome', 'minimal');
  main.replaceChildren(viewer);
}

/**
 * @param {string} label
 * @param {string} code
 */
function snippet(label, code) {
  const button = el('button', { type: 'button' }, ['Copy']);
  button.onclick = () => void navigator.clipboard?.writeText(code).then(() => (button.textContent = 'Copied'));
  return el('div', { class: 'snippet' }, [el('p', {}, [label, ' ', button]), el('pre', {}, [el('code', {}, [code])])]);
}
