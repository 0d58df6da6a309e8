// @ts-check
/**
 * The steps of the quality study (thesis §6.6.2, Algorithm 3, corrected):
 * for each step m_a → m_b
 *
 *   loading ─▶ pre ─▶ transition ─▶ post ─▶ answer ─▶ (next step's pre)
 *
 * - `loading`: only for the first step run: m_a is decoded and put on screen;
 * - `pre`: m_a on screen, free interaction, at least T seconds from the
 *   moment the state began; m_b is decoded meanwhile, off screen;
 * - `transition`: T has passed; the switch to m_b is asked for as soon as m_b
 *   is decoded and ready (a slow decode keeps m_a on screen longer);
 * - `post`: m_b on screen from the swap, at least T seconds from the swap;
 * - `answer`: the two questions with interaction locked; the next step's
 *   m_b is prefetched (decoded, not shown) while the visitor answers.
 *
 * A control step (m_a = m_b) has no transition: `pre` then `post`, T each,
 * the same level throughout, the same questions.
 *
 * Each state's elapsed time is measured from that state's own start (the
 * thesis' Algorithm 3 computes it before resetting the transition clock, so
 * its second period never elapses). No DOM, no timers of its own: the clock
 * is injected, so Node tests drive it with a fake one, and the viewer is an
 * interface the page implements.
 */

/** @typedef {'loading' | 'pre' | 'transition' | 'post' | 'answer' | 'done'} StepState */

/**
 * One step of the plan (`GET /api/study/{slug}/session`).
 * @typedef {object} PlanStep
 * @property {number} step 1-based
 * @property {number} from level shown first (m_a)
 * @property {number} to level shown after the transition (m_b; = from on the control step)
 * @property {boolean} control
 */

/**
 * @typedef {object} Clock
 * @property {() => number} now milliseconds
 * @property {(callback: () => void, ms: number) => unknown} setTimeout
 * @property {(handle: unknown) => void} clearTimeout
 */

/**
 * What the machine asks of the viewer. It answers through
 * {@link StepMachine#ready} and {@link StepMachine#shown}.
 * @typedef {object} StudyView
 * @property {(level: number) => void} prepare decode `level` and make it ready to draw, without showing it
 * @property {(level: number) => void} display put `level` on screen (asked only once it is ready)
 * @property {(locked: boolean) => void} lock the canvas ignores pointer, wheel and keys while locked
 */

/**
 * A state entered: `at` is the clock's time it began.
 * @typedef {{ step: number, state: StepState, at: number }} StateChange
 */

/**
 * The answer's timing, for `PUT …/answers/{step}`.
 * @typedef {{ step: number, shownMs: [number, number] }} AnswerTiming
 */

export class StepMachine {
  /** @type {StepState} */
  state = 'loading';
  /** Index into steps of the step running. */
  #index = 0;
  /** When the current state began (clock ms). */
  #since = 0;
  /** When the current step's pre and post periods began. */
  #preAt = 0;
  #postAt = 0;
  /** When the questions appeared. */
  #answerAt = 0;
  /** Highest level the viewer reported ready, and the level on screen. */
  #ready = -1;
  #shown = -1;
  #displayAsked = -1;
  #saving = false;
  /** @type {unknown} */
  #timer = null;
  /** Every state entered, in order (with the step it belongs to). @type {StateChange[]} */
  history = [];

  /**
   * @param {object} options
   * @param {PlanStep[]} options.steps the steps still to run, in order (a resumed session: from its next step)
   * @param {number} options.seconds T: the least time each period lasts
   * @param {Clock} options.clock
   * @param {StudyView} options.view
   * @param {(change: StateChange) => void} [options.onState]
   */
  constructor({ steps, seconds, clock, view, onState }) {
    if (steps.length === 0) throw new Error('a study machine needs at least one step');
    this.steps = steps;
    this.periodMs = seconds * 1000;
    this.clock = clock;
    this.view = view;
    this.onState = onState ?? (() => {});
  }

  /** The step running (or the last one, when done). */
  get current() {
    return this.steps[Math.min(this.#index, this.steps.length - 1)];
  }

  /** Starts the first step: its m_a is asked for, and `pre` begins once it is on screen. */
  start() {
    this.#enter('loading', this.clock.now());
    this.view.lock(false);
    this.view.prepare(this.current.from);
    this.#maybeDisplay(this.current.from);
  }

  /**
   * The viewer: `level` is decoded and ready to draw (a later level implies the earlier ones).
   * @param {number} level
   */
  ready(level) {
    this.#ready = Math.max(this.#ready, level);
    if (this.state === 'loading') this.#maybeDisplay(this.current.from);
    else if (this.state === 'transition') this.#maybeDisplay(this.current.to);
  }

  /**
   * The viewer: `level` is on screen since `at` (clock ms; default now).
   * @param {number} level
   * @param {number} [at]
   */
  shown(level, at) {
    const now = this.clock.now();
    this.#shown = level;
    const step = this.current;
    if (this.state === 'loading' && level === step.from) {
      this.#startPre(now);
    } else if (this.state === 'transition' && level === step.to) {
      // The post period starts at the swap (never before the transition began).
      this.#startPost(Math.min(now, Math.max(at ?? now, this.#since)));
    }
  }

  /**
   * The visitor submitted the questions: the timing to send with the
   * answer, or null outside the questions (or while one is being saved).
   * @returns {AnswerTiming | null}
   */
  answer() {
    if (this.state !== 'answer' || this.#saving) return null;
    this.#saving = true;
    const step = this.current;
    return { step: step.step, shownMs: [this.#postAt - this.#preAt, this.#answerAt - this.#postAt] };
  }

  /** Saving the answer failed: the questions stay, the visitor may submit again. */
  failed() {
    this.#saving = false;
  }

  /**
   * The server stored the answer: the next step's pre period starts now
   * (its m_a is the level on screen), or the study is done.
   */
  saved() {
    if (this.state !== 'answer' || !this.#saving) return;
    this.#saving = false;
    this.#index++;
    const now = this.clock.now();
    if (this.#index >= this.steps.length) {
      this.#enter('done', now);
      return;
    }
    this.view.lock(false);
    const step = this.current;
    if (this.#shown === step.from) {
      this.#startPre(now);
    } else {
      // A plan whose next step does not start where the last one ended.
      this.#enter('loading', now);
      this.view.prepare(step.from);
      this.#maybeDisplay(step.from);
    }
  }

  /** Stops the timers (the page is leaving). */
  stop() {
    if (this.#timer !== null) this.clock.clearTimeout(this.#timer);
    this.#timer = null;
  }

  /** Milliseconds the current state has lasted. */
  elapsed() {
    return this.clock.now() - this.#since;
  }

  /** @param {number} level */
  #maybeDisplay(level) {
    if (this.#ready < level || this.#displayAsked === level) return;
    this.#displayAsked = level;
    this.view.display(level);
  }

  /** @param {number} at */
  #startPre(at) {
    this.#preAt = at;
    this.#enter('pre', at);
    const step = this.current;
    // m_b is decoded while m_a is on screen.
    if (!step.control) this.view.prepare(step.to);
    this.#arm();
  }

  /** @param {number} at */
  #startPost(at) {
    this.#postAt = at;
    this.#enter('post', at);
    this.#arm();
  }

  #startAnswer() {
    const now = this.clock.now();
    this.#answerAt = now;
    this.view.lock(true);
    this.#enter('answer', now);
    const next = this.steps[this.#index + 1];
    if (next) this.view.prepare(next.to);
  }

  /**
   * @param {StepState} state
   * @param {number} at
   */
  #enter(state, at) {
    this.state = state;
    this.#since = at;
    const change = { step: this.current.step, state, at };
    this.history.push(change);
    this.onState(change);
  }

  /** Wakes at the end of the current period, measured from this state's own start. */
  #arm() {
    if (this.#timer !== null) this.clock.clearTimeout(this.#timer);
    const remaining = Math.max(0, this.periodMs - this.elapsed());
    this.#timer = this.clock.setTimeout(() => this.#tick(), remaining);
  }

  #tick() {
    this.#timer = null;
    if (this.state !== 'pre' && this.state !== 'post') return;
    // Timers may fire a little early: wait out the rest.
    if (this.elapsed() < this.periodMs) {
      this.#arm();
      return;
    }
    const now = this.clock.now();
    if (this.state === 'post') {
      this.#startAnswer();
    } else if (this.current.control) {
      this.#startPost(now);
    } else {
      this.#enter('transition', now);
      this.#maybeDisplay(this.current.to);
    }
  }
}
