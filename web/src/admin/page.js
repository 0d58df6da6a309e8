// @ts-check
/**
 * `/admin`: curators publish from the browser. Paste the curator token
 * (kept in sessionStorage, sent as a Bearer header), upload a scan with its
 * title, description, audience policy, colour mode, unit, up axis, credit
 * line and licence, follow the ingest jobs (polled from /api/jobs, so they
 * resume after a reload; failures show the importer's message), and per
 * model list versions, withdraw or restore one, set its good-enough level,
 * change its credit and licence, and edit its texts in other languages
 * (texts.js). Plain HTML controls with labels; the
 * status lines are live regions.
 */

import { t } from '../i18n/index.js';
import * as api from './api.js';
import { TAG_INPUT, TextsEditor, tagSuggestions } from './texts.js';
import { TourEditor } from './tours.js';

const POLICIES = ['exhibition', 'open', 'researchers', 'open-download', 'exhibition-download'];
/** Each option's value and what it shows: the value itself, or a catalogue key for the empty default. */
const COLOURS = [['', 'admin.colour.default'], ...['ccc', 'vertex', 'vertex-metric', 'none'].map((c) => [c, c])];
const UNITS = [['', 'admin.unit.unknown'], ...['mm', 'cm', 'm', 'in'].map((u) => [u, u])];
const UP_AXES = [['', 'admin.up.detect'], ...['x', 'y', 'z', '-x', '-y', '-z'].map((a) => [a, a])];
/** @param {string[]} option @returns {string} */
const optionText = ([value, shown]) => (value === '' ? t(shown) : shown);
/** The server's limit on a credit line, in bytes (maxlength counts characters: the server has the last word). */
const CREDIT_MAX = 300;
/** Form fields sent only when set: the server's defaults apply otherwise. */
const OPTIONAL_FIELDS = ['language', 'colour', 'unit', 'up', 'credit', 'licence'];
const STYLE = `
.admin { max-width: 60rem; margin: 0 auto; padding: 1rem; line-height: 1.5; }
.admin section { margin: 1.5rem 0; }
.admin label { display: block; margin: 0.5rem 0 0.2rem; }
.admin input, .admin select, .admin textarea, .admin button { font: inherit; max-width: 100%; }
.admin input[type=text], .admin input[type=password], .admin textarea { width: 100%; box-sizing: border-box; }
.admin button { margin: 0.5rem 0.5rem 0 0; }
.admin .jobs li, .admin .versions li { margin: 0.4rem 0; }
.admin .error { color: #b00020; }
.admin progress { width: 10rem; vertical-align: middle; }
.admin .rights { margin: 0.3rem 0 0 1rem; }
.admin .texts { margin: 0.5rem 0 0 1rem; }
.admin .texts h3 { font-size: 1rem; margin: 0.5rem 0; }
.admin .texts fieldset { margin: 0.8rem 0; }
.admin .tour-viewer { display: block; width: 100%; height: 420px; margin: 0.5rem 0; }
.admin .tour-steps li { margin: 0.8rem 0; }
`;

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

/** @param {string} id @param {string} text @param {HTMLElement} control */
function field(id, text, control) {
  control.id = id;
  return el('div', {}, [el('label', { for: id }, [text]), control]);
}

/**
 * A select of the licences, first "— not stated —" (empty).
 * @param {Record<string, string>} attributes
 * @param {api.Licence[]} licences
 * @param {string | null} [selected] a licence id
 */
function licenceSelect(attributes, licences, selected = null) {
  const select = /** @type {HTMLSelectElement} */ (el('select', attributes, [el('option', { value: '' }, [t('admin.licence.none')])]));
  addLicences(select, licences);
  select.value = selected ?? '';
  return select;
}

/** @param {HTMLSelectElement} select @param {api.Licence[]} licences */
function addLicences(select, licences) {
  select.append(...licences.map((l) => el('option', { value: l.id }, [l.name])));
}

/** @param {unknown} e */
function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

/** @param {HTMLElement} main */
export function start(main) {
  document.title = t('admin.title');
  document.head.append(el('style', {}, [STYLE]));
  const page = new AdminPage(main);
  void page.refresh();
  return page;
}

export class AdminPage {
  /** @param {HTMLElement} main */
  constructor(main) {
    this.tokenInput = /** @type {HTMLInputElement} */ (el('input', { type: 'password', autocomplete: 'off' }));
    this.tokenStatus = el('p', { role: 'status' });
    this.uploadStatus = el('p', { role: 'status' });
    this.jobList = el('ul', { class: 'jobs', 'aria-live': 'polite' });
    this.modelList = el('ul', { class: 'models-admin' });
    /** @type {ReturnType<typeof setTimeout> | undefined} */
    this.timer = undefined;
    /** The models listed last (slugs and titles), so a refresh that finds the same leaves the list alone. */
    this.modelsKey = '';
    /** `GET /api/licences` (public), asked once; an empty list when it fails (the upload says why). */
    this.licences = api.licences().catch((e) => {
      this.uploadStatus.textContent = t('admin.licences', { reason: messageOf(e) });
      return /** @type {api.Licence[]} */ ([]);
    });
    this.form = this.uploadForm();
    main.replaceChildren(
      el('div', { class: 'admin' }, [
        el('h1', {}, [t('admin.title')]),
        el('section', { 'aria-labelledby': 'token-h' }, [
          el('h2', { id: 'token-h' }, [t('admin.token.heading')]),
          field('token', t('admin.token.field'), this.tokenInput),
          this.button(t('admin.token.use'), () => this.useToken()),
          this.button(t('admin.token.forget'), () => this.forget()),
          this.tokenStatus,
        ]),
        el('section', { 'aria-labelledby': 'upload-h' }, [el('h2', { id: 'upload-h' }, [t('admin.upload.heading')]), this.form, this.uploadStatus]),
        el('section', { 'aria-labelledby': 'jobs-h' }, [el('h2', { id: 'jobs-h' }, [t('admin.jobs.heading')]), this.jobList]),
        el('section', { 'aria-labelledby': 'models-h' }, [el('h2', { id: 'models-h' }, [t('admin.models.heading')]), this.modelList]),
        tagSuggestions(),
      ]),
    );
    this.tokenStatus.textContent = api.savedToken() ? t('admin.token.set') : t('admin.token.none');
  }

  /** @param {string} text @param {() => unknown} action */
  button(text, action, type = 'button') {
    const b = el('button', { type }, [text]);
    if (type === 'button') b.addEventListener('click', () => void action());
    return b;
  }

  uploadForm() {
    const form = /** @type {HTMLFormElement} */ (el('form', { 'aria-label': t('admin.upload.heading') }));
    const policy = el('select', { name: 'policy' }, POLICIES.map((p) => el('option', { value: p }, [p])));
    const options = (/** @type {string[][]} */ list) => list.map((o) => el('option', { value: o[0] }, [optionText(o)]));
    const colour = el('select', { name: 'colour' }, options(COLOURS));
    const unit = el('select', { name: 'unit' }, options(UNITS));
    const up = el('select', { name: 'up' }, options(UP_AXES));
    const licence = licenceSelect({ name: 'licence' }, []);
    void this.licences.then((list) => addLicences(licence, list));
    form.append(
      field('file', t('admin.field.file'), el('input', { type: 'file', name: 'file', required: '', accept: '.ply,.obj,.off,.glb,.gltf,.md2' })),
      field('slug', t('admin.field.slug'), el('input', { type: 'text', name: 'slug', required: '', pattern: '[a-z0-9]([a-z0-9-]{0,62}[a-z0-9])?' })),
      field('title', t('admin.field.title'), el('input', { type: 'text', name: 'title', required: '' })),
      field('description', t('admin.field.description'), el('textarea', { name: 'description', rows: '3' })),
      field('language', t('admin.field.language'), el('input', { ...TAG_INPUT, name: 'language' })),
      field('policy', t('admin.field.policy'), policy),
      field('colour', t('admin.field.colour'), colour),
      field('unit', t('admin.field.unit'), unit),
      field('up', t('admin.field.up'), up),
      field('credit', t('admin.field.credit'), el('input', { type: 'text', name: 'credit', maxlength: String(CREDIT_MAX) })),
      field('licence', t('admin.field.licence'), licence),
      this.button(t('admin.upload'), () => {}, 'submit'),
    );
    form.addEventListener('submit', (event) => {
      event.preventDefault();
      void this.submit(form);
    });
    return form;
  }

  /** @param {HTMLFormElement} form */
  async submit(form) {
    const data = new FormData(form);
    for (const name of OPTIONAL_FIELDS) if (String(data.get(name) ?? '').trim() === '') data.delete(name);
    this.uploadStatus.textContent = t('admin.uploading');
    try {
      const { job } = await api.upload(data);
      this.uploadStatus.textContent = t('admin.uploaded', { job: String(job) });
      form.reset();
    } catch (e) {
      this.uploadStatus.textContent = t('admin.refused', { reason: messageOf(e) });
    }
    await this.refresh();
  }

  useToken() {
    api.saveToken(this.tokenInput.value.trim() || null);
    this.tokenInput.value = '';
    this.tokenStatus.textContent = api.savedToken() ? t('admin.token.set') : t('admin.token.none');
    void this.refresh();
  }

  forget() {
    api.saveToken(null);
    this.tokenStatus.textContent = t('admin.token.none');
    this.jobList.replaceChildren();
  }

  /** Reloads jobs and models; polls again, fast while a job is under way. */
  async refresh() {
    clearTimeout(this.timer);
    let busy = false;
    if (api.savedToken()) {
      try {
        const jobs = await api.jobs();
        busy = jobs.some((j) => j.state === 'queued' || j.state === 'running');
        this.showJobs(jobs);
      } catch (e) {
        this.jobList.replaceChildren(el('li', { class: 'error' }, [t('admin.jobs.failed', { reason: messageOf(e) })]));
      }
    }
    await this.showModels();
    this.timer = setTimeout(() => void this.refresh(), busy ? 500 : 5000);
  }

  /** @param {api.Job[]} jobs */
  showJobs(jobs) {
    if (jobs.length === 0) {
      this.jobList.replaceChildren(el('li', {}, [t('admin.jobs.none')]));
      return;
    }
    this.jobList.replaceChildren(
      ...jobs.map((j) => {
        const item = el('li', { 'data-job': String(j.id), 'data-state': j.state }, [
          // The state and the stage are the service's words (queued, running, done, failed).
          t('admin.job', { title: j.title, slug: j.slug, file: j.source_name, state: j.state }),
          ' ',
          el('progress', { max: '1', value: String(j.progress), 'aria-label': t('admin.job.progress', { slug: j.slug }) }),
          ` ${j.stage}`,
        ]);
        if (j.state === 'failed') item.append(el('div', { class: 'error' }, [j.error ?? t('admin.job.failed')]));
        if (j.state === 'done') item.append(' ', el('a', { href: `/m/${j.slug}` }, [t('admin.job.open', { version: String(j.model_version) })]));
        return item;
      }),
    );
  }

  async showModels() {
    try {
      const models = await api.models();
      // The same models: only the open version lists are read again (a new version, a status).
      const key = JSON.stringify(models.map((m) => [m.slug, m.title]));
      if (key === this.modelsKey) {
        for (const item of this.modelList.querySelectorAll('li[data-open]')) {
          const list = /** @type {HTMLElement} */ (item.querySelector('ul.versions'));
          void this.showVersions(/** @type {HTMLElement} */ (item), String(item.getAttribute('data-slug')), list, { poll: true });
        }
        return;
      }
      this.modelsKey = key;
      const open = new Set(
        [...this.modelList.querySelectorAll('li[data-open]')].map((li) => li.getAttribute('data-slug')),
      );
      this.modelList.replaceChildren(
        ...models.map((m) => {
          const versions = el('ul', { class: 'versions' });
          const item = el('li', { 'data-slug': m.slug }, [
            el('a', { href: `/m/${m.slug}` }, [m.title]),
            ' ',
            this.button(t('admin.versions', { slug: m.slug }), () => this.showVersions(item, m.slug, versions)),
            this.button(t('admin.tours', { slug: m.slug }), () => this.showTours(item, m.slug)),
            versions,
          ]);
          if (open.has(m.slug)) void this.showVersions(item, m.slug, versions);
          return item;
        }),
      );
    } catch (e) {
      this.modelsKey = '';
      this.modelList.replaceChildren(el('li', { class: 'error' }, [t('admin.models.failed', { reason: messageOf(e) })]));
    }
  }

  /**
   * The model's guided tours and their editor (tours.js), under its entry;
   * the page's refresh leaves them alone (the model list is kept while the same).
   * @param {HTMLElement} item @param {string} slug
   */
  async showTours(item, slug) {
    let editor = this.tourEditors.get(slug);
    if (!editor) {
      editor = new TourEditor(slug);
      this.tourEditors.set(slug, editor);
    }
    if (!item.contains(editor.root)) item.append(editor.root);
    await editor.refresh();
  }

  /** @type {Map<string, TourEditor>} */
  tourEditors = new Map();

  /**
   * @param {HTMLElement} item @param {string} slug @param {HTMLElement} list
   * @param {{ poll?: boolean }} [options] `poll`: the page's own refresh, which leaves a version a curator is editing alone
   */
  async showVersions(item, slug, list, { poll = false } = {}) {
    item.setAttribute('data-open', '');
    try {
      const [versions, licences] = await Promise.all([api.versions(slug), this.licences]);
      if (poll && list.querySelector('[data-editing]')) return;
      list.replaceChildren(...versions.map((v) => this.versionItem(slug, v, list, item, licences)));
    } catch (e) {
      list.replaceChildren(el('li', { class: 'error' }, [messageOf(e)]));
    }
  }

  /**
   * @param {string} slug @param {api.Version} v @param {HTMLElement} list @param {HTMLElement} item
   * @param {api.Licence[]} licences
   */
  versionItem(slug, v, list, item, licences) {
    const id = `level-${slug}-${v.version}`;
    const level = /** @type {HTMLInputElement} */ (
      el('input', { type: 'number', id, min: '0', max: String(v.levels - 1), value: v.good_enough_level === null ? '' : String(v.good_enough_level) })
    );
    const status = el('span', { role: 'status' });
    /** @param {api.VersionChange} change */
    const apply = async (change) => {
      try {
        await api.changeVersion(slug, v.version, change);
        await this.showVersions(item, slug, list);
      } catch (e) {
        status.textContent = messageOf(e);
      }
    };
    const version = String(v.version);
    const withdraw = v.status === 'ready' ? t('admin.version.withdraw', { version }) : t('admin.version.restore', { version });
    const entry = el('li', { 'data-version': version }, [
      // The status and the policy are the service's words.
      t('admin.version', { version, status: v.status, count: v.levels, policy: v.policy }),
      ' ',
      this.button(withdraw, () => apply({ status: v.status === 'ready' ? 'withdrawn' : 'ready' })),
      el('label', { for: id }, [t('admin.version.goodEnough')]),
      level,
      this.button(t('admin.version.setLevel'), () => apply({ good_enough_level: level.value === '' ? null : Number(level.value) })),
      status,
      this.rightsForm(slug, v, licences, apply),
      this.textsToggle(slug, v.version),
    ]);
    const editing = () => entry.setAttribute('data-editing', '');
    entry.addEventListener('input', editing);
    entry.addEventListener('change', editing);
    // An open texts editor survives the list being written again, and holds off the page's polling.
    const texts = this.textEditors.get(`${slug}/${v.version}`);
    if (texts) {
      entry.append(texts.root);
      editing();
    }
    return entry;
  }

  /** @type {Map<string, TextsEditor>} the texts editors opened, by slug and version */
  textEditors = new Map();

  /**
   * The button that opens (and closes) a version's texts in other languages.
   * @param {string} slug @param {number} version
   */
  textsToggle(slug, version) {
    const key = `${slug}/${version}`;
    const toggle = this.button(t('admin.texts.open', { version: String(version) }), async () => {
      const entry = /** @type {HTMLElement} */ (toggle.closest('li'));
      let editor = this.textEditors.get(key);
      if (editor) {
        editor.root.remove();
        this.textEditors.delete(key);
        entry.removeAttribute('data-editing');
        toggle.setAttribute('aria-expanded', 'false');
        return;
      }
      editor = new TextsEditor(slug, version);
      this.textEditors.set(key, editor);
      entry.setAttribute('data-editing', '');
      entry.append(editor.root);
      toggle.setAttribute('aria-expanded', 'true');
      await editor.load();
    });
    toggle.setAttribute('aria-expanded', String(this.textEditors.has(key)));
    return toggle;
  }

  /**
   * A version's credit and licence as recorded, and a form to change them
   * (empty clears). The server's message shows in the version's status line.
   * @param {string} slug @param {api.Version} v @param {api.Licence[]} licences
   * @param {(change: api.VersionChange) => Promise<void>} apply
   */
  rightsForm(slug, v, licences, apply) {
    const version = String(v.version);
    const name = licences.find((l) => l.id === v.licence)?.name ?? v.licence;
    const credit = /** @type {HTMLInputElement} */ (
      el('input', { type: 'text', id: `credit-${slug}-${v.version}`, maxlength: String(CREDIT_MAX) })
    );
    credit.value = v.credit ?? '';
    const licence = licenceSelect({ id: `licence-${slug}-${v.version}` }, licences, v.licence ?? null);
    const form = /** @type {HTMLFormElement} */ (
      el('form', { class: 'rights', 'aria-label': t('admin.rights', { version }) }, [
        el('p', { class: 'rights-now' }, [
          t('admin.rights.now', { credit: v.credit ?? t('admin.rights.notStated'), licence: name ?? t('admin.rights.notStated') }),
        ]),
        el('label', { for: credit.id }, [t('admin.rights.credit', { version })]),
        credit,
        el('label', { for: licence.id }, [t('admin.rights.licence', { version })]),
        licence,
        this.button(t('admin.rights.save', { version }), () => {}, 'submit'),
      ])
    );
    form.addEventListener('submit', (event) => {
      event.preventDefault();
      void apply({ credit: credit.value.trim(), licence: licence.value });
    });
    return form;
  }
}
