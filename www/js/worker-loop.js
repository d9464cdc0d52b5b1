// The worker side of the page's one job-worker protocol (workers.js is the page side), used by
// the map, multi-target, Monte Carlo and plan workers. Messages in:
//   {type: 'init', module}     first: instantiates the page's compiled wasm module (no re-compile);
//   {type: 'job', gen, ...}    a job; only the newest matters: older jobs still waiting are dropped
//                              (a drag posts one per pointer move);
//   {type: 'cancel', gen}      drops every job older than gen (a waiting one, and a running one at
//                              its next pause).
// Messages out:
//   {type: 'ready'}                        the module is instantiated;
//   {type: 'start', gen}                   the job begins (the page knows which job runs and since
//                                          when, and may terminate the worker when it went stale);
//   {type: 'progress', gen, ...}           what the job reports while it runs (`progress` below);
//   {type: 'result', gen, ms, ...}         the job's result (ms: its time in the worker);
//   {type: 'error', gen, message}          the job failed (also when the module did not load);
//   {type: 'dropped', gen}                 the job was dropped at a pause (superseded or
//                                          cancelled): the worker is free (issue 24: the page
//                                          terminates a worker whose stale job does not pause).

import init from '../pkg/scatterloc.js';
import { errorText } from './dom.js';

/** Thrown by `pause` when a newer job or a cancel has arrived: the job ends without a message. */
const SUPERSEDED = Symbol('superseded');

/** Lets queued messages (a newer job, a cancel) in. */
const yieldTask = () => new Promise((resolve) => setTimeout(resolve, 0));

/**
 * Serves jobs with `compute(job, {progress, pause})`, which returns (or resolves to) {value,
 * transfer?}: `value` (an object) is merged into the result message, `transfer` lists its
 * ArrayBuffers to move, not copy. While it runs a job may call `progress(value, transfer?)` to
 * post {type: 'progress', gen, ...value}, and a sliced job `await pause()` between slices: it lets
 * queued messages in and throws (ending the job silently) if a newer job or a cancel arrived.
 */
export function serveLatest(compute) {
  let ready = null;
  let latest = null; // the newest job not yet started
  let newest = 0; // generation of the newest job or cancel received
  let busy = false;

  async function run(m) {
    const gen = m.gen;
    const progress = (value, transfer = []) => self.postMessage({ type: 'progress', gen, ...value }, transfer);
    const pause = async () => {
      await yieldTask();
      if (gen < newest) throw SUPERSEDED;
    };
    try {
      await ready;
      if (gen < newest) return; // cancelled while the module loaded
      self.postMessage({ type: 'start', gen });
      const t0 = performance.now();
      const { value, transfer = [] } = await compute(m, { progress, pause });
      self.postMessage({ type: 'result', gen, ms: performance.now() - t0, ...value }, transfer);
    } catch (err) {
      if (err === SUPERSEDED) self.postMessage({ type: 'dropped', gen });
      else self.postMessage({ type: 'error', gen, message: errorText(err) });
    }
  }

  async function loop() {
    busy = true;
    try {
      while (latest) {
        const m = latest;
        latest = null;
        await run(m);
        await yieldTask(); // lets newer jobs in
      }
    } finally {
      busy = false;
    }
  }

  self.onmessage = (e) => {
    const m = e.data;
    if (m.type === 'init') {
      ready = init({ module_or_path: m.module }).then(() => self.postMessage({ type: 'ready' }));
      ready.catch(() => {}); // reported by the job that awaits it
      return;
    }
    newest = Math.max(newest, m.gen);
    if (m.type === 'cancel') {
      if (latest && latest.gen < m.gen) latest = null;
      return;
    }
    latest = m;
    if (!busy) loop();
  };
}
