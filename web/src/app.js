// @ts-check
/**
 * The pages `vitrine serve` maps to one index.html: the gallery at `/`, a
 * model page at `/m/{slug}` (viewer, description, embed snippets) and the
 * bare viewer at `/embed/{slug}` for iframes, and the quality study at
 * `/study/{slug}?invitation=…` (study/page.js). `?device=`, `?token=`,
 * `?level=`, `?offscreen=off`, `?decoders=`, `?antialias=`, `?motion=`, `?iiif-content=`, `?tour=`, `?step=`, `?refine=` and `?vertex-budget=` on a page's URL are passed to the viewer, and so is a shared view in its fragment (view-state.js).
 */

import './element.js';
import { chooseText, markLanguage } from './content-language.js';
import { onLanguageChange, t } from './i18n/index.js';
import { startLanguage } from './i18n/switch.js';
import { fetchResults } from './study/api.js';
import { readContentState } from './content-state.js';
import { contentStateMessage } from './share.js';
import { StudyPage } from './study/page.js';

startLanguage();
const main = /** @type {HTMLElement} */ (document.getElementById('app'));
const params = new URLSearchParams(location.search);
const route = location.pathname.match(/^\/(m|embed|study)\/([a-z0-9-]+)\/?$/);

if (!route && location.pathname === '/' && params.has('iiif-content')) void contentStatePage(params.get('iiif-content') ?? '');
else if (!route) void (location.pathname === '/admin' ? import('./admin/page.js').then((admin) => admin.start(main)) : gallery());
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
  for (const key of ['device', 'token', 'level', 'offscreen', 'decoders', 'antialias', 'motion', 'iiif-content', 'tour', 'step', 'refine', 'vertex-budget']) {
    const value = params.get(key);
    if (value !== null) viewer.setAttribute(key, value);
  }
  // A shared view travels in the fragment (view-state.js).
  if (location.hash.length > 1) viewer.setAttribute('view', location.hash.slice(1));
  return viewer;
}

/**
 * The model list, written again in the visitor's language when it changes.
 * @typedef {{ slug: string, title: string, levels: number, page_url: string, thumbnail?: string | null,
 *   language?: string | null, translations?: Record<string, { title?: string }> }} ListedModel
 */
async function gallery() {
  document.body.classList.add('gallery');
  /** @type {{ models: ListedModel[] } | { error: string } | null} */
  let answer = null;
  const draw = () => {
    const list = el('ul', { class: 'models' });
    main.replaceChildren(el('header', {}, [el('h1', {}, [siteName()]), el('p', {}, [t('gallery.intro')])]), list);
    if (answer === null) return;
    if ('error' in answer) {
      list.append(el('li', { class: 'error', role: 'alert' }, [t('gallery.failed', { reason: answer.error })]));
      return;
    }
    if (answer.models.length === 0) list.append(el('li', {}, [t('gallery.empty')]));
    for (const m of answer.models) {
      const levels = el('small', {}, [t('gallery.levels', { count: m.levels })]);
      // The title in the visitor's language where the museum gave one (content-language.js).
      const title = chooseText(m, 'title');
      const name = el('strong', {}, [title.text]);
      markLanguage(name, title.lang);
      list.append(el('li', {}, [el('a', { href: m.page_url }, [thumbnail(title.text, m.thumbnail), name, levels])]));
    }
  };
  draw();
  onLanguageChange(draw);
  try {
    const response = await fetch('/api/models', { cache: 'no-store' });
    if (!response.ok) throw new Error(t('gallery.status', { status: String(response.status) }));
    answer = await response.json();
  } catch (error) {
    answer = { error: error instanceof Error ? error.message : String(error) };
  }
  draw();
}

/**
 * `/?iiif-content=…`: the model a IIIF Content State names, opened at its
 * view; a Content State that names another site, no model of this one or
 * nothing readable gets a message (and no request leaves for another host).
 * @param {string} value
 */
async function contentStatePage(value) {
  /** @type {() => string} */
  let problem;
  try {
    const { slug } = readContentState(value, { origin: location.origin, prefix: '' });
    const response = await fetch('/api/models', { cache: 'no-store' });
    const listed = response.ok ? /** @type {{ models: ListedModel[] }} */ (await response.json()).models : [];
    if (listed.some((m) => m.slug === slug)) return modelPage(slug);
    problem = () => t('contentState.unknown', { name: slug });
  } catch (error) {
    problem = () => contentStateMessage(error);
  }
  const draw = () =>
    main.replaceChildren(
      el('header', {}, [el('h1', {}, [siteName()])]),
      el('p', { class: 'error', role: 'alert' }, [problem()]),
      el('p', {}, [el('a', { href: '/' }, [t('page.allModels')])]),
    );
  draw();
  onLanguageChange(draw);
}

/** The site's name as the server states it (`--site-name`). */
function siteName() {
  return document.querySelector('meta[name="application-name"]')?.getAttribute('content') || 'Vitrine';
}

/**
 * The model's picture (rendered at ingest), lazily loaded in a box of
 * fixed aspect so the grid does not move as pictures arrive; a neutral
 * placeholder when the server has none (or an older server, without the field).
 * @param {string} title
 * @param {string | null | undefined} src
 */
function thumbnail(title, src) {
  const box = el('span', { class: 'thumb' });
  if (typeof src === 'string' && src) {
    const img = el('img', { src, alt: t('gallery.preview', { title }), loading: 'lazy', decoding: 'async', width: '320', height: '240' });
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
  // The page around the viewer, in the visitor's language; the viewer stays
  // where it is (moving it would start it again).
  const header = el('header');
  const embed = el('section', { class: 'embed' });
  main.replaceChildren(header, viewer, embed);
  const draw = () => {
    const iframe =
      `<iframe src="${origin}/embed/${slug}" width="800" height="600" style="border:0" ` +
      `allow="fullscreen" allowfullscreen title="${t('page.iframeTitle').replace(/"/g, '&quot;')}"></iframe>`;
    const element =
      `<script type="module" src="${origin}/vitrine.js"></script>\n` +
      `<vitrine-viewer src="${origin}/m/${slug}" style="width:800px;height:600px"></vitrine-viewer>`;
    header.replaceChildren(el('a', { href: '/' }, [t('page.allModels')]));
    embed.replaceChildren(
      el('h2', {}, [t('page.embed')]),
      snippet(t('page.embedIframe'), iframe),
      snippet(t('page.embedElement'), element),
    );
  };
  draw();
  onLanguageChange(draw);
  // The quality study's answers, asked only when the manifest links them
  // (a model without a study would answer 404, a failed request).
  viewer.addEventListener(
    'vitrine-level',
    () => {
      const manifest = /** @type {any} */ (viewer).viewer?.manifest;
      if (!manifest?.study_results) return;
      void fetchResults(slug)
        .then((results) => {
          if (results) /** @type {any} */ (viewer).viewer?.ui.setStudy(results.levels);
        })
        .catch(() => {});
    },
    { once: true },
  );
  // The tab's title: the model's, in the visitor's language where the museum gave one.
  const retitle = () => {
    const manifest = /** @type {any} */ (viewer).viewer?.manifest;
    const title = manifest ? chooseText(manifest, 'title').text : '';
    if (title) document.title = `${title} · ${siteName()}`;
  };
  viewer.addEventListener('vitrine-level', retitle);
  onLanguageChange(retitle);
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
  const button = el('button', { type: 'button' }, [t('page.copy')]);
  button.onclick = () => void navigator.clipboard?.writeText(code).then(() => (button.textContent = t('page.copied')));
  return el('div', { class: 'snippet' }, [el('p', {}, [label, ' ', button]), el('pre', {}, [el('code', {}, [code])])]);
}
