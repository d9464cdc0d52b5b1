// Planner worker (a module Web Worker): runs the core's plan_network off the page's main thread
// (plan.js). The wasm call is synchronous, so the page cancels a plan by terminating this worker
// (and starts a fresh one for the next plan: the compiled module is handed over, as to the other
// workers, so that takes milliseconds).
//
// Messages in: {type: 'init', module} (first), then {type: 'run', id, scenario (JSON text),
// request (JSON text)}. Messages out: {type: 'ready'}; {type: 'progress', id, evaluations,
// budget, points: [[evaluations, best]], improvement: null | {evaluations, best, scenario (JSON
// text)}} at most every PROGRESS_MS, or every IMPROVEMENT_MS (a frame) when there is an
// improvement (every improvement's point is delivered; of the layouts the newest since the last
// message, which is all the page shows); {type: 'done', id, result (plan.json), ms};
// {type: 'error', id, message}.

import init, { plan_network } from '../pkg/scatterloc.js';
import { errorText } from './dom.js';

/** Least time between progress messages, ms (about 30 per second)… */
const PROGRESS_MS = 33;
/** …or between messages carrying an improvement (about one per frame). */
const IMPROVEMENT_MS = 16;

let ready = null;

self.onmessage = (e) => {
  const m = e.data;
  if (m.type === 'init') {
    ready = init({ module_or_path: m.module }).then(() => self.postMessage({ type: 'ready' }));
    ready.catch(() => {}); // reported by the run that awaits it
    return;
  }
  if (m.type === 'run') {
    run(m).catch((err) => self.postMessage({ type: 'error', id: m.id, message: errorText(err) }));
  }
};

async function run(m) {
  await ready;
  const t0 = performance.now();
  let last = -Infinity;
  let points = [];
  let improvement = null;
  let progress = null;
  const flush = () => {
    self.postMessage({
      type: 'progress', id: m.id, evaluations: progress.evaluations, budget: progress.budget, points,
      improvement: improvement && { ...improvement, scenario: JSON.stringify(improvement.scenario) },
    });
    points = [];
    improvement = null;
    last = performance.now();
  };
  const result = plan_network(m.scenario, m.request, (p) => {
    progress = p;
    if (p.improvement) {
      points.push([p.evaluations, p.improvement.best]);
      improvement = { evaluations: p.evaluations, best: p.improvement.best, scenario: p.improvement.scenario };
    }
    const since = performance.now() - last;
    if (since >= PROGRESS_MS || (improvement && since >= IMPROVEMENT_MS)) flush();
    return true;
  });
  if (progress && (points.length || improvement)) flush();
  self.postMessage({ type: 'done', id: m.id, result, ms: performance.now() - t0 });
}
