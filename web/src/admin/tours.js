// @ts-check
/**
 * Recording guided tours in `/admin`: per model, its tours (every version's,
 * newest versions' first) with edit and delete, and an editor beside the
 * viewer: the curator frames a view, adds it as a step, writes the step's
 * title and text (Markdown) in the language chosen for editing (each
 * language kept apart), shows, retakes, moves and removes steps, and saves
 * (`POST`/`PUT /api/admin/models/{slug}/tours`; a reorder is a save). The
 * server's refusal shows in the status line.
 */

import { formatView, parseView } from '../view-state.js';
import { LANGUAGES } from '../i18n/languages.js';
import { language, t } from '../i18n/index.js';
import * as api from './api.js';

/**
 * @typedef {{ view: string, title: Record<string, string>, text: Record<string, string> }} DraftStep
 * @typedef {{ id: number | null, version?: number, title: Record<string, string>, steps: DraftStep[] }} Draft
 */

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

/** @param {string} text @param {() => unknown} action @param {Record<string, string>} [attributes] */
function button(text, action, attributes = {}) {
  const b = el('button', { type: 'button', ...attributes }, [text]);
  b.addEventListener('click', () => void action());
  return b;
}

/** @param {Record<string, string>} map @param {string} lang */
function shown(map, lang) {
  return map[lang] ?? map.en ?? Object.values(map)[0] ?? '';
}

/** @param {unknown} e */
function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

export class TourEditor {
  /** @type {api.Tour[]} */
  tours = [];
  /** @type {Draft | null} */
  draft = null;
  /** The language the curator writes in (a BCP 47 tag). @type {string} */
  lang = language();

  /** @param {string} slug */
  constructor(slug) {
    this.slug = slug;
    this.status = el('p', { role: 'status' });
    this.list = el('ul', { class: 'tours' });
    this.editor = el('div', { class: 'tour-editor' });
    this.root = el('section', { class: 'tours-admin', 'aria-label': t('admin.tours.heading', { slug }) }, [
      el('h3', {}, [t('admin.tours.heading', { slug })]),
      this.list,
      button(t('admin.tours.new'), () => this.edit({ id: null, title: {}, steps: [] })),
      this.editor,
      this.status,
    ]);
  }

  async refresh() {
    try {
      this.tours = await api.tours(this.slug);
    } catch (e) {
      this.status.textContent = t('admin.tours.failed', { reason: messageOf(e) });
      return;
    }
    const lang = this.lang;
    this.list.replaceChildren(
      ...(this.tours.length === 0
        ? [el('li', {}, [t('admin.tours.none')])]
        : this.tours.map((tour) => {
            const title = shown(tour.title, lang);
            return el('li', { 'data-tour': String(tour.id) }, [
              t('admin.tours.item', { title, version: String(tour.version), count: tour.steps.length }),
              ' ',
              el('a', { href: `/m/${this.slug}?tour=${tour.id}&step=1` }, [t('admin.tours.open', { title })]),
              ' ',
              button(t('admin.tours.edit', { title }), () =>
                this.edit({
                  id: tour.id,
                  version: tour.version,
                  title: { ...tour.title },
                  steps: tour.steps.map((s) => ({ view: s.view, title: { ...s.title }, text: { ...s.text } })),
                }),
              ),
              button(t('admin.tours.delete', { title }), () => this.remove(tour.id)),
            ]);
          })),
    );
  }

  /** @param {number} id */
  async remove(id) {
    try {
      await api.deleteTour(this.slug, id);
      this.status.textContent = t('admin.tours.deleted');
      if (this.draft?.id === id) this.close();
    } catch (e) {
      this.status.textContent = t('admin.tours.failed', { reason: messageOf(e) });
    }
    await this.refresh();
  }

  close() {
    this.draft = null;
    this.editor.replaceChildren();
  }

  /** The editor for a tour, with the model's viewer to frame the views in. @param {Draft} draft */
  edit(draft) {
    this.draft = draft;
    this.viewer = el('vitrine-viewer', { src: `/api/models/${this.slug}`, chrome: 'full', class: 'tour-viewer' });
    this.steps = el('ol', { class: 'tour-steps' });
    const languages = /** @type {HTMLSelectElement} */ (
      el('select', { id: `tour-lang-${this.slug}` }, LANGUAGES.map((l) => el('option', { value: l.code, lang: l.code }, [l.name])))
    );
    languages.value = this.lang;
    languages.addEventListener('change', () => {
      this.lang = languages.value;
      this.#draw();
    });
    this.titleInput = /** @type {HTMLInputElement} */ (el('input', { type: 'text', id: `tour-title-${this.slug}`, maxlength: '200' }));
    this.titleInput.addEventListener('input', () => this.#write(draft.title, this.titleInput?.value ?? ''));
    this.editor.replaceChildren(
      this.viewer,
      el('label', { for: languages.id }, [t('admin.tours.language')]),
      languages,
      el('label', { for: this.titleInput.id }, [t('admin.tours.title')]),
      this.titleInput,
      button(t('admin.tours.addStep'), () => this.addStep()),
      this.steps,
      button(t('admin.tours.save'), () => this.save()),
      button(t('admin.tours.close'), () => this.close()),
    );
    this.#draw();
  }

  /** @param {Record<string, string>} map @param {string} value */
  #write(map, value) {
    if (value.trim() === '') delete map[this.lang];
    else map[this.lang] = value;
  }

  /** The view on screen in the editor's viewer, as a step's view; null before the model is. */
  #viewOnScreen() {
    const viewer = /** @type {any} */ (this.viewer)?.viewer;
    if (!viewer?.camera) return null;
    return formatView(viewer.share.current());
  }

  addStep() {
    const view = this.#viewOnScreen();
    if (!this.draft || view === null) {
      this.status.textContent = t('admin.tours.noView');
      return;
    }
    this.draft.steps.push({ view, title: {}, text: {} });
    this.#draw();
    const fields = this.steps?.querySelectorAll('input') ?? [];
    /** @type {HTMLInputElement | undefined} */ (fields[fields.length - 1])?.focus();
  }

  /** Writes the title and steps in the editing language. */
  #draw() {
    const draft = this.draft;
    if (!draft || !this.steps || !this.titleInput) return;
    this.titleInput.value = draft.title[this.lang] ?? '';
    this.steps.replaceChildren(
      ...draft.steps.map((step, k) => {
        const n = k + 1;
        const id = `tour-${this.slug}-step-${n}`;
        const title = /** @type {HTMLInputElement} */ (el('input', { type: 'text', id: `${id}-title`, maxlength: '200' }));
        title.value = step.title[this.lang] ?? '';
        title.addEventListener('input', () => this.#write(step.title, title.value));
        const text = /** @type {HTMLTextAreaElement} */ (el('textarea', { id: `${id}-text`, rows: '3' }));
        text.value = step.text[this.lang] ?? '';
        text.addEventListener('input', () => this.#write(step.text, text.value));
        const move = (/** @type {number} */ by) => {
          const to = k + by;
          if (to < 0 || to >= draft.steps.length) return;
          [draft.steps[k], draft.steps[to]] = [draft.steps[to], draft.steps[k]];
          this.#draw();
          /** @type {HTMLElement | null} */ (this.steps?.querySelector(`[data-step="${to + 1}"] .${by < 0 ? 'up' : 'down'}`) ?? null)?.focus();
        };
        return el('li', { 'data-step': String(n) }, [
          el('label', { for: title.id }, [t('admin.tours.stepTitle', { n })]),
          title,
          el('label', { for: text.id }, [t('admin.tours.stepText', { n })]),
          text,
          button(t('admin.tours.show', { n }), () => this.#show(step)),
          button(t('admin.tours.retake', { n }), () => {
            const view = this.#viewOnScreen();
            if (view !== null) step.view = view;
          }),
          button(t('admin.tours.up', { n }), () => move(-1), { class: 'up' }),
          button(t('admin.tours.down', { n }), () => move(1), { class: 'down' }),
          button(t('admin.tours.remove', { n }), () => {
            draft.steps.splice(k, 1);
            this.#draw();
          }),
        ]);
      }),
    );
  }

  /** @param {DraftStep} step */
  #show(step) {
    const viewer = /** @type {any} */ (this.viewer)?.viewer;
    if (!viewer?.camera) return;
    viewer.share.apply(parseView(step.view));
  }

  async save() {
    const draft = this.draft;
    if (!draft) return;
    /** @type {api.TourInput} */
    const body = { title: draft.title, steps: draft.steps };
    if (draft.version !== undefined) body.version = draft.version;
    try {
      const saved = await api.saveTour(this.slug, draft.id, body);
      draft.id = saved.id;
      draft.version = saved.version;
      this.status.textContent = t('admin.tours.saved');
    } catch (e) {
      this.status.textContent = t('admin.tours.failed', { reason: messageOf(e) });
    }
    await this.refresh();
  }
}
