// @ts-check
/**
 * The quality study's page, `/study/{slug}?invitation=TOKEN` (thesis
 * §6.6.2): information, consent (nothing is stored before it: the session
 * is created by the consent's POST), a practice view, the original at its
 * last level as a replayable turntable, then the steps run by machine.js,
 * each ending with the two questions. The model is shown as §6.6.1 asks:
 * colour on, free interaction, the whole window, a black background.
 */

import '../element.js';
import { formatNumber, t } from '../i18n/index.js';
import { StudyApi, StudyError } from './api.js';
import { ViewLog } from './log.js';
import { StepMachine } from './machine.js';

/** @typedef {import('./api.js').StudyPlan} StudyPlan */
/** @typedef {import('../element.js').VitrineViewerElement} ViewerElement */
/** @typedef {import('../viewer.js').Viewer} Viewer */

/** One turn of the original's turntable. */
const TURNTABLE_MS = 15_000;

/** The two questions (thesis §6.6.2); values as the API takes them, texts as catalogue keys. */
export const QUESTIONS = {
  improvement: {
    legend: 'study.improvement',
    options: /** @type {const} */ ([
      ['none', 'study.improvement.none'],
      ['a-little', 'study.improvement.aLittle'],
      ['improved', 'study.improvement.improved'],
      ['greatly', 'study.improvement.greatly'],
    ]),
  },
  sufficient: {
    legend: 'study.sufficient',
    options: /** @type {const} */ ([
      ['yes', 'study.sufficient.yes'],
      ['no', 'study.sufficient.no'],
    ]),
  },
};

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

/** @param {string} label */
function button(label, attributes = {}) {
  return /** @type {HTMLButtonElement} */ (el('button', { type: 'button', ...attributes }, [label]));
}

/** The device class the session records: from the pointer and the screen. */
export function deviceClass() {
  const coarse = matchMedia('(pointer: coarse)').matches;
  if (!coarse) return 'desktop';
  return Math.min(screen.width, screen.height) < 600 ? 'phone' : 'tablet';
}

export class StudyPage {
  /** @type {StudyPlan | null} */
  plan = null;
  /** @type {StepMachine | null} */
  machine = null;
  /** @type {ViewLog | null} */
  log = null;
  /** @type {ViewerElement | null} */
  viewerElement = null;

  /**
   * @param {HTMLElement} main
   * @param {string} slug
   * @param {URLSearchParams} params
   */
  constructor(main, slug, params) {
    this.main = main;
    this.slug = slug;
    this.invitation = params.get('invitation') ?? '';
    this.offscreen = params.get('offscreen');
    this.api = new StudyApi(slug, this.invitation);
    this.status = el('p', { class: 'study-status', role: 'status', 'aria-live': 'polite' });
    this.stage = el('div', { class: 'study-stage' });
    this.panel = el('div', { class: 'study-panel' });
    document.body.classList.add('study');
  }

  async start() {
    this.main.replaceChildren(this.stage, this.panel);
    if (!this.invitation) {
      this.#closed('This study is closed: the link has no invitation.');
      return;
    }
    let info;
    try {
      info = await this.api.info();
    } catch (error) {
      if (error instanceof StudyError && error.status === 403) this.#closed(t('study.closed', { reason: error.message }));
      else if (error instanceof StudyError && error.status === 404) this.#closed(t('study.noModel'));
      else this.#closed(t('study.loadFailed', { reason: reason(error) }));
      return;
    }
    document.title = t('study.tabTitle', { title: info.title });
    if (info.invitation === 'finished') {
      this.#message(t('study.thanks'), t('study.alreadyInvitation'));
      return;
    }
    this.#information(info);
  }

  /** @param {string} text */
  #closed(text) {
    document.body.classList.add('study-closed');
    this.panel.className = 'study-panel study-page';
    this.panel.replaceChildren(el('h1', {}, [t('study.heading')]), el('p', { role: 'alert' }, [text]));
  }

  /** @param {string} title @param {string} text */
  #message(title, text) {
    this.#removeViewer();
    this.panel.className = 'study-panel study-page';
    const heading = el('h1', { tabindex: '-1' }, [title]);
    this.panel.replaceChildren(heading, el('p', {}, [text]), this.status);
    heading.focus();
  }

  /** @param {import('./api.js').StudyInfo} info */
  #information(info) {
    this.panel.className = 'study-panel study-page';
    const minutes = Math.max(1, Math.round((info.step_count * (2 * info.seconds + 10) + 60) / 60));
    const next = button(t('study.continue'), { class: 'primary' });
    const heading = el('h1', { tabindex: '-1' }, [t('study.titled', { title: info.title })]);
    this.panel.replaceChildren(
      heading,
      el('p', {}, [t('study.intro'), ' ', t('study.duration', { count: minutes })]),
      el('ol', {}, [
        el('li', {}, [t('study.plan.practice')]),
        el('li', {}, [t('study.plan.original')]),
        el('li', {}, [t('study.plan.steps', { count: info.step_count, time: formatSeconds(info.seconds) })]),
      ]),
      el('p', {}, [t('study.plan.questions')]),
      el('dl', {}, [
        el('dt', {}, [t(QUESTIONS.improvement.legend)]),
        el('dd', {}, [t('study.improvement.help')]),
        el('dt', {}, [t(QUESTIONS.sufficient.legend)]),
        el('dd', {}, [t('study.sufficient.help')]),
      ]),
      el('p', { class: 'actions' }, [next]),
    );
    if (info.invitation === 'started') {
      heading.after(el('p', { class: 'study-resume' }, [t('study.resume')]));
    }
    heading.focus();
    next.onclick = () => this.#consent();
  }

  #consent() {
    const box = /** @type {HTMLInputElement} */ (el('input', { type: 'checkbox', id: 'study-consent' }));
    const start = button(t('study.start'), { class: 'primary' });
    const heading = el('h1', { tabindex: '-1' }, [t('study.consent')]);
    this.panel.replaceChildren(
      heading,
      el('p', {}, [t('study.consent.stored')]),
      el('p', {}, [t('study.consent.nothing')]),
      el('p', { class: 'consent' }, [box, el('label', { for: 'study-consent' }, [t('study.consent.agree')])]),
      el('p', { class: 'actions' }, [start]),
      this.status,
    );
    heading.focus();
    start.onclick = async () => {
      if (!box.checked) {
        this.#say(t('study.consent.tick'));
        box.focus();
        return;
      }
      start.disabled = true;
      this.#say(t('study.starting'));
      try {
        const plan = await this.api.start({
          device: deviceClass(),
          viewport: [innerWidth, innerHeight],
          pixel_ratio: devicePixelRatio,
        });
        this.#begin(plan);
      } catch (error) {
        start.disabled = false;
        if (error instanceof StudyError && error.status === 409) this.#message(t('study.thanks'), t('study.already'));
        else this.#say(t('study.startFailed', { reason: reason(error) }));
      }
    };
  }

  /** @param {StudyPlan} plan */
  #begin(plan) {
    this.plan = plan;
    const origin = performance.now();
    this.log = new ViewLog({
      send: (events) => this.api.views(events),
      now: () => performance.now(),
      origin,
      camera: () => this.viewerElement?.viewer?.camera ?? null,
    });
    this.log.start();
    addEventListener('pagehide', () => void this.log?.flush());
    if (plan.finished || plan.next_step === null) {
      void this.#finish();
      return;
    }
    if (plan.answered.length > 0) this.#steps();
    else this.#practice();
  }

  /**
   * A viewer in the stage: the model up to `hold`, black background, no chrome.
   * @param {number} hold
   */
  #mountViewer(hold) {
    this.#removeViewer();
    const element = /** @type {ViewerElement} */ (el('vitrine-viewer', {
      src: `/api/models/${this.slug}`,
      token: this.invitation,
      hold: String(hold),
      background: '#000000',
      chrome: 'none',
      // Participants judge each level as it is: never a coarser one while it turns (motion.js).
      motion: 'full',
    }));
    if (this.offscreen) element.setAttribute('offscreen', this.offscreen);
    element.addEventListener('vitrine-interaction', (event) => {
      const kind = /** @type {CustomEvent<{ kind: import('../controls.js').Interaction }>} */ (event).detail.kind;
      this.log?.interaction(kind);
    });
    element.addEventListener('vitrine-error', (event) => {
      this.#say(t('study.modelFailed', { reason: /** @type {CustomEvent<{ message: string }>} */ (event).detail.message }));
    });
    this.stage.replaceChildren(element);
    this.viewerElement = element;
    return /** @type {Viewer} */ (element.viewer);
  }

  #removeViewer() {
    this.viewerElement?.remove();
    this.viewerElement = null;
  }

  #practice() {
    const plan = /** @type {StudyPlan} */ (this.plan);
    const level = Math.max(0, Math.floor(plan.last_level / 2));
    const viewer = this.#mountViewer(level);
    this.log?.enter(0, 'practice');
    const next = button(t('study.continue'), { class: 'primary' });
    this.panel.className = 'study-panel study-overlay';
    this.panel.replaceChildren(
      el('h2', {}, [t('study.practice')]),
      el('p', {}, [t('study.practice.help')]),
      el('p', { class: 'actions' }, [next]),
      this.status,
    );
    this.#say(t('study.practice.loading'));
    void viewer.whenShown(level).then(() => this.#say(t('study.practice.ready')));
    next.focus();
    next.onclick = () => this.#original(viewer);
  }

  /** @param {Viewer} viewer */
  #original(viewer) {
    const plan = /** @type {StudyPlan} */ (this.plan);
    const last = plan.last_level;
    this.log?.enter(0, 'original');
    viewer.display(last);
    const replay = button(t('study.replay'));
    const begin = button(t('study.begin'), { class: 'primary' });
    replay.disabled = true;
    this.panel.replaceChildren(
      el('h2', {}, [t('study.original')]),
      el('p', {}, [t('study.original.help')]),
      el('p', { class: 'actions' }, [replay, begin]),
      this.status,
    );
    this.#say(t('study.original.loading'));
    const turn = () => {
      replay.disabled = true;
      this.#say(t('study.original.turning'));
      void viewer.turntable(TURNTABLE_MS).then(() => {
        replay.disabled = false;
        if (this.viewerElement?.viewer === viewer) this.#say(t('study.original.done'));
      });
    };
    void viewer.whenShown(last).then(turn);
    replay.onclick = turn;
    begin.focus();
    begin.onclick = () => {
      viewer.stopTurntable();
      this.#steps();
    };
  }

  /** The steps still to answer, from the plan's next step on. */
  #steps() {
    const plan = /** @type {StudyPlan} */ (this.plan);
    const steps = plan.steps.filter((s) => !plan.answered.includes(s.step) && s.step >= (plan.next_step ?? 1));
    const first = steps[0];
    const viewer = this.#mountViewer(first.from);
    this.panel.className = 'study-panel study-overlay';
    this.panel.replaceChildren(this.status);
    const machine = new StepMachine({
      steps,
      seconds: plan.seconds,
      clock: { now: () => performance.now(), setTimeout: (f, ms) => setTimeout(f, ms), clearTimeout: (h) => clearTimeout(/** @type {any} */ (h)) },
      view: {
        prepare: (level) => {
          viewer.prefetch(level);
          void viewer.whenReady(level).then(() => machine.ready(level));
        },
        display: (level) => {
          viewer.display(level);
          void viewer.whenShown(level).then((at) => machine.shown(level, at));
        },
        lock: (on) => viewer.setLocked(on),
      },
      onState: (change) => this.#stateChanged(change),
    });
    this.machine = machine;
    machine.start();
  }

  /** @param {import('./machine.js').StateChange} change */
  #stateChanged(change) {
    const plan = /** @type {StudyPlan} */ (this.plan);
    const total = plan.steps.length;
    document.body.dataset.studyState = change.state;
    if (change.state === 'done') {
      void this.#finish();
      return;
    }
    if (change.state === 'loading') {
      this.panel.replaceChildren(this.status);
      this.#say(t('study.step.loading', { step: change.step, total }));
      return;
    }
    this.log?.enter(change.step, change.state, change.at);
    if (change.state === 'answer') {
      this.#questions(change.step, total);
      return;
    }
    if (change.state === 'pre') {
      this.panel.replaceChildren(this.status);
      this.#say(t('study.step.look', { step: change.step, total }));
    }
  }

  /**
   * The two questions, with the canvas locked (machine.js asked for it).
   * @param {number} step
   * @param {number} total
   */
  #questions(step, total) {
    const form = /** @type {HTMLFormElement} */ (el('form', { class: 'study-questions', 'aria-labelledby': 'study-q-title' }));
    const title = el('h2', { id: 'study-q-title' }, [t('study.step.answers', { step, total })]);
    const submit = /** @type {HTMLButtonElement} */ (el('button', { type: 'submit', class: 'primary' }, [t('study.submit')]));
    form.append(title, radioGroup('improvement', step), radioGroup('sufficient', step), el('p', { class: 'actions' }, [submit]));
    this.panel.replaceChildren(form, this.status);
    this.#say(t('study.step.paused', { step, total }));
    /** @type {HTMLInputElement | null} */ (form.querySelector('input'))?.focus();
    form.onsubmit = async (event) => {
      event.preventDefault();
      const data = new FormData(form);
      const improvement = data.get('improvement');
      const sufficient = data.get('sufficient');
      if (!improvement || !sufficient) {
        this.#say(t('study.answerBoth'));
        return;
      }
      const machine = /** @type {StepMachine} */ (this.machine);
      const timing = machine.answer();
      if (!timing) return;
      submit.disabled = true;
      this.#say(t('study.saving'));
      try {
        await this.api.answer(timing.step, {
          improvement: /** @type {import('./api.js').Improvement} */ (String(improvement)),
          sufficient: sufficient === 'yes',
          shown_ms: [Math.round(timing.shownMs[0]), Math.round(timing.shownMs[1])],
        });
      } catch (error) {
        machine.failed();
        submit.disabled = false;
        this.#say(t('study.saveFailed', { reason: reason(error) }));
        return;
      }
      void this.log?.flush();
      machine.saved();
    };
  }

  async #finish() {
    this.machine?.stop();
    this.#say(t('study.finishing'));
    try {
      await this.log?.flush();
      await this.api.finish();
    } catch (error) {
      this.#say(t('study.finishFailed', { reason: reason(error) }));
      return;
    } finally {
      this.log?.stop();
    }
    this.#message(t('study.thanks'), t('study.saved'));
    this.#say(t('study.complete'));
  }

  /** @param {string} text */
  #say(text) {
    this.status.textContent = text;
  }
}

/**
 * A question as a fieldset of radio buttons with labels.
 * @param {'improvement' | 'sufficient'} name
 * @param {number} step
 */
function radioGroup(name, step) {
  const question = QUESTIONS[name];
  const legend = el('legend', {}, [t(question.legend)]);
  const fieldset = el('fieldset', { class: `study-q study-q-${name}` }, [legend]);
  for (const [value, label] of question.options) {
    const id = `study-${step}-${name}-${value}`;
    const input = el('input', { type: 'radio', name, value, id, required: '' });
    fieldset.append(el('label', { for: id }, [input, ' ', t(label)]));
  }
  return fieldset;
}

/** @param {number} seconds a step's time, in the page's language ("4 seconds", "4 segundos") */
function formatSeconds(seconds) {
  return seconds >= 1
    ? formatNumber(Number(seconds.toFixed(1)), { style: 'unit', unit: 'second', unitDisplay: 'long' })
    : formatNumber(Math.round(seconds * 1000), { style: 'unit', unit: 'millisecond' });
}

/** @param {unknown} error the reason to show after a translated sentence */
function reason(error) {
  return error instanceof Error ? error.message : String(error);
}
