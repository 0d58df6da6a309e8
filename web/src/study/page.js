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
import { StudyApi, StudyError } from './api.js';
import { ViewLog } from './log.js';
import { StepMachine } from './machine.js';

/** @typedef {import('./api.js').StudyPlan} StudyPlan */
/** @typedef {import('../element.js').VitrineViewerElement} ViewerElement */
/** @typedef {import('../viewer.js').Viewer} Viewer */

/** One turn of the original's turntable. */
const TURNTABLE_MS = 15_000;

/** The two questions (thesis §6.6.2); values as the API takes them. */
export const QUESTIONS = {
  improvement: {
    legend: 'Did you perceive an improvement during this step?',
    options: /** @type {const} */ ([
      ['none', 'None'],
      ['a-little', 'A little'],
      ['improved', 'Improved'],
      ['greatly', 'Greatly'],
    ]),
  },
  sufficient: {
    legend: 'Is this quality sufficient?',
    options: /** @type {const} */ ([
      ['yes', 'Yes'],
      ['no', 'No'],
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
      if (error instanceof StudyError && error.status === 403) this.#closed(`This study is closed. ${error.message}`);
      else if (error instanceof StudyError && error.status === 404) this.#closed('There is no such model.');
      else this.#closed(`The study could not be loaded: ${error instanceof Error ? error.message : error}`);
      return;
    }
    document.title = `Quality study: ${info.title} · Vitrine`;
    if (info.invitation === 'finished') {
      this.#message('Thank you', 'You have already taken part in this study with this invitation.');
      return;
    }
    this.#information(info);
  }

  /** @param {string} text */
  #closed(text) {
    document.body.classList.add('study-closed');
    this.panel.className = 'study-panel study-page';
    this.panel.replaceChildren(el('h1', {}, ['Quality study']), el('p', { role: 'alert' }, [text]));
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
    const next = button('Continue', { class: 'primary' });
    const heading = el('h1', { tabindex: '-1' }, [`Quality study: ${info.title}`]);
    this.panel.replaceChildren(
      heading,
      el('p', {}, [
        'You will look at a 3D scan while it is shown at increasing levels of detail, and say what you see. ',
        `It takes about ${minutes} minutes.`,
      ]),
      el('ol', {}, [
        el('li', {}, ['A short practice: turn and zoom the model to get used to the controls.']),
        el('li', {}, ['The original at its full detail, turning by itself (you can replay it).']),
        el('li', {}, [
          `${info.step_count} steps. In each, the model is shown for at least ${formatSeconds(info.seconds)}, `,
          `its detail may then change, and it is shown for at least ${formatSeconds(info.seconds)} more. `,
          'You may turn and zoom it freely meanwhile.',
        ]),
      ]),
      el('p', {}, ['After each step the model stops responding and two questions appear:']),
      el('dl', {}, [
        el('dt', {}, [QUESTIONS.improvement.legend]),
        el('dd', {}, ['None, a little, improved, or greatly: whether the model looked better by the end of the step than at its start. If unsure, answer "Improved".']),
        el('dt', {}, [QUESTIONS.sufficient.legend]),
        el('dd', {}, ['Yes or no: whether the model as it is now shown would be good enough for you to look at the object.']),
      ]),
      el('p', { class: 'actions' }, [next]),
    );
    if (info.invitation === 'started') {
      heading.after(el('p', { class: 'study-resume' }, ['You have started this study before: it continues where you left off.']));
    }
    heading.focus();
    next.onclick = () => this.#consent();
  }

  #consent() {
    const box = /** @type {HTMLInputElement} */ (el('input', { type: 'checkbox', id: 'study-consent' }));
    const start = button('Start', { class: 'primary' });
    const heading = el('h1', { tabindex: '-1' }, ['Consent']);
    this.panel.replaceChildren(
      heading,
      el('p', {}, [
        'If you agree, this page stores your answers, how you moved the camera during the study, ',
        'and your kind of device, window size and pixel ratio. They are kept under a random participant ',
        'code, never with your name or address, and used only to choose how much detail this model needs.',
      ]),
      el('p', {}, ['Nothing is stored unless you agree. You may stop at any time by closing the page.']),
      el('p', { class: 'consent' }, [box, el('label', { for: 'study-consent' }, ['I agree to take part and to the storing described above'])]),
      el('p', { class: 'actions' }, [start]),
      this.status,
    );
    heading.focus();
    start.onclick = async () => {
      if (!box.checked) {
        this.#say('Please tick the box to agree first, or close the page to leave.');
        box.focus();
        return;
      }
      start.disabled = true;
      this.#say('Starting…');
      try {
        const plan = await this.api.start({
          device: deviceClass(),
          viewport: [innerWidth, innerHeight],
          pixel_ratio: devicePixelRatio,
        });
        this.#begin(plan);
      } catch (error) {
        start.disabled = false;
        if (error instanceof StudyError && error.status === 409) this.#message('Thank you', 'You have already taken part in this study.');
        else this.#say(`The study could not start: ${error instanceof Error ? error.message : error}`);
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
      this.#say(`The model could not be shown: ${/** @type {CustomEvent<{ message: string }>} */ (event).detail.message}`);
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
    const next = button('Continue', { class: 'primary' });
    this.panel.className = 'study-panel study-overlay';
    this.panel.replaceChildren(
      el('h2', {}, ['Practice']),
      el('p', {}, ['Drag to turn the model, scroll or pinch to zoom, right-drag or drag with two fingers to move it. Arrow keys turn it, + and − zoom, when it has focus.']),
      el('p', { class: 'actions' }, [next]),
      this.status,
    );
    this.#say('Practice: the model is loading.');
    void viewer.whenShown(level).then(() => this.#say('Practice: try the controls, then continue.'));
    next.focus();
    next.onclick = () => this.#original(viewer);
  }

  /** @param {Viewer} viewer */
  #original(viewer) {
    const plan = /** @type {StudyPlan} */ (this.plan);
    const last = plan.last_level;
    this.log?.enter(0, 'original');
    viewer.display(last);
    const replay = button('Replay');
    const begin = button('Begin the steps', { class: 'primary' });
    replay.disabled = true;
    this.panel.replaceChildren(
      el('h2', {}, ['The original']),
      el('p', {}, ['This is the model at its full detail, turning once. Replay it as often as you like, then begin.']),
      el('p', { class: 'actions' }, [replay, begin]),
      this.status,
    );
    this.#say('The original is loading…');
    const turn = () => {
      replay.disabled = true;
      this.#say('The original, turning.');
      void viewer.turntable(TURNTABLE_MS).then(() => {
        replay.disabled = false;
        if (this.viewerElement?.viewer === viewer) this.#say('The original: replay it, or begin the steps.');
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
      this.#say(`Step ${change.step} of ${total}: the model is loading.`);
      return;
    }
    this.log?.enter(change.step, change.state, change.at);
    if (change.state === 'answer') {
      this.#questions(change.step, total);
      return;
    }
    if (change.state === 'pre') {
      this.panel.replaceChildren(this.status);
      this.#say(`Step ${change.step} of ${total}: look at the model; you may turn and zoom it. The questions follow.`);
    }
  }

  /**
   * The two questions, with the canvas locked (machine.js asked for it).
   * @param {number} step
   * @param {number} total
   */
  #questions(step, total) {
    const form = /** @type {HTMLFormElement} */ (el('form', { class: 'study-questions', 'aria-labelledby': 'study-q-title' }));
    const title = el('h2', { id: 'study-q-title' }, [`Step ${step} of ${total}: your answers`]);
    const submit = /** @type {HTMLButtonElement} */ (el('button', { type: 'submit', class: 'primary' }, ['Submit answers']));
    form.append(title, radioGroup('improvement', step), radioGroup('sufficient', step), el('p', { class: 'actions' }, [submit]));
    this.panel.replaceChildren(form, this.status);
    this.#say(`Step ${step} of ${total}: the model is paused. Answer the two questions.`);
    /** @type {HTMLInputElement | null} */ (form.querySelector('input'))?.focus();
    form.onsubmit = async (event) => {
      event.preventDefault();
      const data = new FormData(form);
      const improvement = data.get('improvement');
      const sufficient = data.get('sufficient');
      if (!improvement || !sufficient) {
        this.#say('Please answer both questions.');
        return;
      }
      const machine = /** @type {StepMachine} */ (this.machine);
      const timing = machine.answer();
      if (!timing) return;
      submit.disabled = true;
      this.#say('Saving your answers…');
      try {
        await this.api.answer(timing.step, {
          improvement: /** @type {import('./api.js').Improvement} */ (String(improvement)),
          sufficient: sufficient === 'yes',
          shown_ms: [Math.round(timing.shownMs[0]), Math.round(timing.shownMs[1])],
        });
      } catch (error) {
        machine.failed();
        submit.disabled = false;
        this.#say(`Your answers could not be saved: ${error instanceof Error ? error.message : error}. Please try again.`);
        return;
      }
      void this.log?.flush();
      machine.saved();
    };
  }

  async #finish() {
    this.machine?.stop();
    this.#say('Finishing…');
    try {
      await this.log?.flush();
      await this.api.finish();
    } catch (error) {
      this.#say(`The study could not be finished: ${error instanceof Error ? error.message : error}`);
      return;
    } finally {
      this.log?.stop();
    }
    this.#message('Thank you', 'Your answers are saved. You may close this page.');
    this.#say('The study is complete.');
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
  const legend = el('legend', {}, [question.legend]);
  const fieldset = el('fieldset', { class: `study-q study-q-${name}` }, [legend]);
  for (const [value, label] of question.options) {
    const id = `study-${step}-${name}-${value}`;
    const input = el('input', { type: 'radio', name, value, id, required: '' });
    fieldset.append(el('label', { for: id }, [input, ` ${label}`]));
  }
  return fieldset;
}

/** @param {number} seconds */
function formatSeconds(seconds) {
  return seconds >= 1 ? `${Number(seconds.toFixed(1))} seconds` : `${Math.round(seconds * 1000)} ms`;
}
