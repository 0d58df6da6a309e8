// @ts-check
// The study's step machine (src/study/machine.js) on a fake clock: each
// period lasts at least T from its own start, m_b is switched in only once
// it is ready (the post period starts at the swap), the questions come only
// after the post period, with interaction locked and the next level
// prefetched; the control step has no transition.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { StepMachine } from '../src/study/machine.js';

const T = 20;

/** A clock whose time moves only when the test says. */
class FakeClock {
  time = 1000;
  /** @type {Array<{ at: number, callback: () => void, id: number }>} */
  timers = [];
  #next = 1;
  now = () => this.time;
  /** @param {() => void} callback @param {number} ms */
  setTimeout = (callback, ms) => {
    const id = this.#next++;
    this.timers.push({ at: this.time + ms, callback, id });
    return id;
  };
  /** @param {unknown} id */
  clearTimeout = (id) => {
    this.timers = this.timers.filter((t) => t.id !== id);
  };
  /** Moves time forward, firing due timers in order. @param {number} ms */
  advance(ms) {
    const end = this.time + ms;
    for (;;) {
      this.timers.sort((a, b) => a.at - b.at);
      const due = this.timers[0];
      if (!due || due.at > end) break;
      this.timers.shift();
      this.time = due.at;
      due.callback();
    }
    this.time = end;
  }
}

/** Records what the machine asks of the viewer. */
function fakeView() {
  /** @type {string[]} */
  const calls = [];
  const view = {
    calls,
    locked: false,
    /** @param {number} level */
    prepare: (level) => calls.push(`prepare ${level}`),
    /** @param {number} level */
    display: (level) => calls.push(`display ${level}`),
    /** @param {boolean} on */
    lock: (on) => {
      view.locked = on;
      calls.push(on ? 'lock' : 'unlock');
    },
  };
  return view;
}

/** @param {Array<[number, number]>} pairs @param {number} [control] 1-based step that is the control */
function steps(pairs, control) {
  return pairs.map(([from, to], i) => ({ step: i + 1, from, to, control: i + 1 === control }));
}

/** @param {import('../src/study/machine.js').StateChange[]} history */
function durations(history) {
  return history.slice(0, -1).map((s, i) => ({ step: s.step, state: s.state, ms: history[i + 1].at - s.at }));
}

test('a step: pre ≥ T, switch when m_b is ready, post ≥ T from the swap, then questions locked', () => {
  const clock = new FakeClock();
  const view = fakeView();
  const machine = new StepMachine({ steps: steps([[0, 1], [1, 2]]), seconds: T, clock, view });
  machine.start();
  assert.equal(machine.state, 'loading');
  assert.deepEqual(view.calls, ['unlock', 'prepare 0']);
  clock.advance(500);
  machine.ready(0);
  assert.deepEqual(view.calls.slice(-1), ['display 0']);
  clock.advance(100);
  machine.shown(0);
  assert.equal(machine.state, 'pre');
  assert.deepEqual(view.calls.slice(-1), ['prepare 1'], 'm_b is decoded while m_a is on screen');
  // m_b is ready early, but the switch waits for the pre period.
  clock.advance(2000);
  machine.ready(1);
  assert.ok(!view.calls.includes('display 1'), 'no switch during the pre period');
  clock.advance(T * 1000 - 2001);
  assert.equal(machine.state, 'pre', '1 ms before T the pre period goes on');
  clock.advance(1);
  assert.equal(machine.state, 'transition');
  assert.deepEqual(view.calls.slice(-1), ['display 1']);
  // The swap takes 300 ms; the post period starts at it.
  clock.advance(300);
  machine.shown(1, clock.now() - 10);
  assert.equal(machine.state, 'post');
  assert.equal(view.locked, false, 'free interaction during the post period');
  clock.advance(T * 1000 - 11);
  assert.equal(machine.state, 'post', 'the post period is measured from the swap');
  assert.equal(machine.answer(), null, 'no answer before the questions');
  clock.advance(1);
  assert.equal(machine.state, 'answer');
  assert.equal(view.locked, true, 'interaction is locked while asking');
  assert.deepEqual(view.calls.slice(-2), ['lock', 'prepare 2'], 'the next level is prefetched when the questions appear');
  const timing = machine.answer();
  assert.deepEqual(timing, { step: 1, shownMs: [T * 1000 + 290, T * 1000] });
  assert.equal(machine.answer(), null, 'one answer at a time');
  machine.saved();
  assert.equal(machine.state, 'pre', 'the next step starts at once on the level on screen');
  assert.equal(machine.current.step, 2);
  assert.equal(view.locked, false);
  const d = durations(machine.history);
  for (const s of d.filter((s) => s.state === 'pre' || s.state === 'post')) {
    assert.ok(s.ms >= T * 1000, `${s.state} of step ${s.step} lasted ${s.ms} ms`);
  }
});

test('a slow decode delays the switch, and the post period starts at the swap', () => {
  const clock = new FakeClock();
  const view = fakeView();
  const machine = new StepMachine({ steps: steps([[2, 3]]), seconds: T, clock, view });
  machine.start();
  machine.ready(2);
  machine.shown(2);
  const preAt = clock.now();
  clock.advance(T * 1000);
  assert.equal(machine.state, 'transition');
  assert.ok(!view.calls.includes('display 3'), 'm_b not ready: m_a stays');
  clock.advance(2 * T * 1000);
  assert.equal(machine.state, 'transition', 'still waiting for m_b, however long');
  machine.ready(3);
  assert.deepEqual(view.calls.slice(-1), ['display 3']);
  clock.advance(700);
  const swapAt = clock.now();
  machine.shown(3, swapAt);
  assert.equal(machine.state, 'post');
  clock.advance(T * 1000 - 1);
  assert.equal(machine.state, 'post', 'post lasts T from the swap, not from the end of pre');
  clock.advance(1);
  assert.equal(machine.state, 'answer');
  assert.deepEqual(machine.answer()?.shownMs, [swapAt - preAt, T * 1000]);
  machine.saved();
  assert.equal(machine.state, 'done');
});

test('timers that fire early are waited out', () => {
  const clock = new FakeClock();
  const view = fakeView();
  const early = { ...clock, now: clock.now, clearTimeout: clock.clearTimeout,
    /** @param {() => void} f @param {number} ms */
    setTimeout: (f, ms) => clock.setTimeout(f, ms > 5 ? ms - 5 : ms) };
  const machine = new StepMachine({ steps: steps([[0, 1]]), seconds: T, clock: early, view });
  machine.start();
  machine.ready(1);
  machine.shown(0);
  clock.advance(T * 1000 - 1);
  assert.equal(machine.state, 'pre');
  clock.advance(1);
  assert.equal(machine.state, 'transition');
});

test('the control step: no transition, the same level for T twice, the same questions', () => {
  const clock = new FakeClock();
  const view = fakeView();
  const machine = new StepMachine({ steps: steps([[0, 1], [1, 1], [1, 2]], 2), seconds: T, clock, view });
  machine.start();
  machine.ready(1);
  machine.shown(0);
  clock.advance(T * 1000);
  machine.shown(1);
  clock.advance(T * 1000);
  assert.equal(machine.state, 'answer');
  machine.answer();
  machine.saved();
  assert.equal(machine.current.control, true);
  assert.equal(machine.state, 'pre');
  const before = view.calls.length;
  clock.advance(T * 1000);
  assert.equal(machine.state, 'post', 'straight from pre to post');
  clock.advance(T * 1000 - 1);
  assert.equal(machine.state, 'post');
  clock.advance(1);
  assert.equal(machine.state, 'answer');
  assert.equal(view.locked, true);
  assert.deepEqual(view.calls.slice(before), ['lock', 'prepare 2'], 'no display on the control step; the next level prefetched');
  assert.deepEqual(machine.answer(), { step: 2, shownMs: [T * 1000, T * 1000] });
  machine.saved();
  assert.equal(machine.current.step, 3);
  const states = machine.history.filter((s) => s.step === 2).map((s) => s.state);
  assert.deepEqual(states, ['pre', 'post', 'answer']);
});

test('a failed save keeps the questions; every state lasts at least T over a whole plan', () => {
  const clock = new FakeClock();
  const view = fakeView();
  const plan = steps([[0, 1], [1, 2], [2, 2], [2, 3]], 3);
  /** @type {string[]} */
  const seen = [];
  const machine = new StepMachine({ steps: plan, seconds: T, clock, view, onState: (c) => seen.push(`${c.step}:${c.state}`) });
  machine.start();
  machine.ready(0);
  machine.shown(0);
  while (machine.state !== 'done') {
    clock.advance(137);
    if (machine.state === 'transition') {
      machine.ready(machine.current.to);
      clock.advance(450);
      machine.shown(machine.current.to);
    } else if (machine.state === 'answer') {
      assert.ok(machine.answer());
      machine.failed();
      assert.equal(machine.state, 'answer');
      assert.ok(machine.answer(), 'submitted again after the failure');
      clock.advance(3000);
      machine.saved();
    }
  }
  assert.equal(seen[0], '1:loading');
  assert.equal(seen.filter((s) => s.endsWith(':answer')).length, 4);
  const d = durations(machine.history);
  for (const s of d.filter((s) => s.state === 'pre' || s.state === 'post')) {
    assert.ok(s.ms >= T * 1000, `${s.state} of step ${s.step} lasted ${s.ms} ms`);
  }
});
