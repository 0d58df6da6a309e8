// @ts-check
/**
 * `/admin`: curators publish from the browser. Paste the curator token
 * (kept in sessionStorage, sent as a Bearer header), upload a scan with its
 * title, description, audience policy and colour mode, follow the ingest
 * jobs (polled from /api/jobs, so they resume after a reload; failures show
 * the importer's message), and per model list versions, withdraw or restore
 * one and set its good-enough level. Plain HTML controls with labels; the
 * status lines are live regions.
 */

import * as api from './api.js';

const POLICIES = ['exhibition', 'open', 'researchers', 'open-download', 'exhibition-download'];
const COLOURS = [['', 'default (ccc for a textured scan)'], ['ccc', 'ccc'], ['vertex', 'vertex'], ['vertex-metric', 'vertex-metric'], ['none', 'none']];
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

/** @param {unknown} e */
function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

/** @param {HTMLElement} main */
export function start(main) {
  document.title = 'Vitrine admin';
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
    this.form = this.uploadForm();
    main.replaceChildren(
      el('div', { class: 'admin' }, [
        el('h1', {}, ['Vitrine admin']),
        el('section', { 'aria-labelledby': 'token-h' }, [
          el('h2', { id: 'token-h' }, ['Curator token']),
          field('token', 'Token (from vitrine token create --scope curator)', this.tokenInput),
          this.button('Use token', () => this.useToken()),
          this.button('Forget token', () => this.forget()),
          this.tokenStatus,
        ]),
        el('section', { 'aria-labelledby': 'upload-h' }, [el('h2', { id: 'upload-h' }, ['Upload a scan']), this.form, this.uploadStatus]),
        el('section', { 'aria-labelledby': 'jobs-h' }, [el('h2', { id: 'jobs-h' }, ['Ingest jobs']), this.jobList]),
        el('section', { 'aria-labelledby': 'models-h' }, [el('h2', { id: 'models-h' }, ['Models']), this.modelList]),
      ]),
    );
    this.tokenStatus.textContent = api.savedToken() ? 'A token is set for this tab.' : 'No token yet.';
  }

  /** @param {string} text @param {() => unknown} action */
  button(text, action, type = 'button') {
    const b = el('button', { type }, [text]);
    if (type === 'button') b.addEventListener('click', () => void action());
    return b;
  }

  uploadForm() {
    const form = /** @type {HTMLFormElement} */ (el('form', { 'aria-label': 'Upload a scan' }));
    const policy = el('select', { name: 'policy' }, POLICIES.map((p) => el('option', { value: p }, [p])));
    const colour = el('select', { name: 'colour' }, COLOURS.map(([v, t]) => el('option', { value: v }, [t])));
    form.append(
      field('file', 'Scan (PLY, OBJ, OFF, GLB, glTF, MD2)', el('input', { type: 'file', name: 'file', required: '', accept: '.ply,.obj,.off,.glb,.gltf,.md2' })),
      field('slug', 'Slug (a-z, 0-9, -)', el('input', { type: 'text', name: 'slug', required: '', pattern: '[a-z0-9]([a-z0-9-]{0,62}[a-z0-9])?' })),
      field('title', 'Title', el('input', { type: 'text', name: 'title', required: '' })),
      field('description', 'Description', el('textarea', { name: 'description', rows: '3' })),
      field('policy', 'Audience policy', policy),
      field('colour', 'Colour mode', colour),
      this.button('Upload', () => {}, 'submit'),
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
    if (data.get('colour') === '') data.delete('colour');
    this.uploadStatus.textContent = 'Uploading…';
    try {
      const { job } = await api.upload(data);
      this.uploadStatus.textContent = `Uploaded: ingest job ${job} started.`;
      form.reset();
    } catch (e) {
      this.uploadStatus.textContent = `Upload refused: ${messageOf(e)}`;
    }
    await this.refresh();
  }

  useToken() {
    api.saveToken(this.tokenInput.value.trim() || null);
    this.tokenInput.value = '';
    this.tokenStatus.textContent = api.savedToken() ? 'A token is set for this tab.' : 'No token yet.';
    void this.refresh();
  }

  forget() {
    api.saveToken(null);
    this.tokenStatus.textContent = 'No token yet.';
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
        this.jobList.replaceChildren(el('li', { class: 'error' }, [`Jobs: ${messageOf(e)}`]));
      }
    }
    await this.showModels();
    this.timer = setTimeout(() => void this.refresh(), busy ? 500 : 5000);
  }

  /** @param {api.Job[]} jobs */
  showJobs(jobs) {
    if (jobs.length === 0) {
      this.jobList.replaceChildren(el('li', {}, ['No uploads yet.']));
      return;
    }
    this.jobList.replaceChildren(
      ...jobs.map((j) => {
        const item = el('li', { 'data-job': String(j.id), 'data-state': j.state }, [
          `${j.title} (${j.slug}, ${j.source_name}): ${j.state}`,
          ' ',
          el('progress', { max: '1', value: String(j.progress), 'aria-label': `progress of ${j.slug}` }),
          ` ${j.stage}`,
        ]);
        if (j.state === 'failed') item.append(el('div', { class: 'error' }, [j.error ?? 'failed']));
        if (j.state === 'done') item.append(' ', el('a', { href: `/m/${j.slug}` }, [`open version ${j.model_version}`]));
        return item;
      }),
    );
  }

  async showModels() {
    try {
      const models = await api.models();
      const open = new Set(
        [...this.modelList.querySelectorAll('li[data-open]')].map((li) => li.getAttribute('data-slug')),
      );
      this.modelList.replaceChildren(
        ...models.map((m) => {
          const versions = el('ul', { class: 'versions' });
          const item = el('li', { 'data-slug': m.slug }, [
            el('a', { href: `/m/${m.slug}` }, [m.title]),
            ' ',
            this.button(`Versions of ${m.slug}`, () => this.showVersions(item, m.slug, versions)),
            versions,
          ]);
          if (open.has(m.slug)) void this.showVersions(item, m.slug, versions);
          return item;
        }),
      );
    } catch (e) {
      this.modelList.replaceChildren(el('li', { class: 'error' }, [`Models: ${messageOf(e)}`]));
    }
  }

  /** @param {HTMLElement} item @param {string} slug @param {HTMLElement} list */
  async showVersions(item, slug, list) {
    item.setAttribute('data-open', '');
    try {
      const versions = await api.versions(slug);
      list.replaceChildren(...versions.map((v) => this.versionItem(slug, v, list, item)));
    } catch (e) {
      list.replaceChildren(el('li', { class: 'error' }, [messageOf(e)]));
    }
  }

  /** @param {string} slug @param {api.Version} v @param {HTMLElement} list @param {HTMLElement} item */
  versionItem(slug, v, list, item) {
    const id = `level-${slug}-${v.version}`;
    const level = /** @type {HTMLInputElement} */ (
      el('input', { type: 'number', id, min: '0', max: String(v.levels - 1), value: v.good_enough_level === null ? '' : String(v.good_enough_level) })
    );
    const status = el('span', { role: 'status' });
    /** @param {{ status?: string, good_enough_level?: number | null }} change */
    const apply = async (change) => {
      try {
        await api.changeVersion(slug, v.version, change);
        await this.showVersions(item, slug, list);
      } catch (e) {
        status.textContent = messageOf(e);
      }
    };
    const withdraw = v.status === 'ready' ? 'Withdraw' : 'Restore';
    return el('li', { 'data-version': String(v.version) }, [
      `Version ${v.version} (${v.status}, ${v.levels} levels, ${v.policy}) `,
      this.button(`${withdraw} version ${v.version}`, () => apply({ status: v.status === 'ready' ? 'withdrawn' : 'ready' })),
      el('label', { for: id }, [`Good-enough level (empty: the 20 % rule)`]),
      level,
      this.button('Set level', () => apply({ good_enough_level: level.value === '' ? null : Number(level.value) })),
      status,
    ]);
  }
}
