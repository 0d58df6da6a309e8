// @ts-check
// What the browser benchmarks share: waiting for a quiet machine before a
// cold load, and medians.
import { readFileSync } from 'node:fs';

/** Busy and total jiffies of every core since boot (/proc/stat). */
function cpuTimes() {
  const [, ...fields] = readFileSync('/proc/stat', 'utf8').split('\n')[0].trim().split(/\s+/);
  const t = fields.map(Number);
  const idle = t[3] + t[4];
  const total = t.reduce((a, b) => a + b, 0);
  return { busy: total - idle, total };
}

/**
 * Waits until the machine's cores were less than 15 % busy over half a
 * second (at most 60 s): a closed page's GPU process can rasterise its last
 * frame for seconds, which would slow the next load.
 */
export async function quiet() {
  const until = performance.now() + 60_000;
  while (performance.now() < until) {
    const a = cpuTimes();
    await new Promise((resolve) => setTimeout(resolve, 500));
    const b = cpuTimes();
    if ((b.busy - a.busy) / Math.max(1, b.total - a.total) < 0.15) return;
  }
}

/** @param {number[]} xs */
export const median = (xs) => [...xs].sort((a, b) => a - b)[xs.length >> 1];
