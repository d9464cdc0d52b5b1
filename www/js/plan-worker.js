// Planner worker (a module Web Worker, served by worker-loop.js): runs the core's plan_network
// off the page's main thread (plan.js). The wasm call is synchronous, so the page cancels a plan
// by terminating this worker (workers.js, staleMs 0; a fresh one starts for the next plan: the
// compiled module is handed over, so that takes milliseconds).
//
// Jobs: {gen, scenario (JSON text), request (JSON text)}. Progress: {gen, evaluations, budget,
// points: [[evaluations, best]], improvement: null | {evaluations, best, scenario (JSON text)}} at
// most every PROGRESS_MS, or every IMPROVEMENT_MS (a frame) when there is an improvement (every
// improvement's point is delivered; of the layouts the newest since the last message, which is
// all the page shows). The result: {result (plan.json)}.

import { plan_network } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

/** Least time between progress messages, ms (about 30 per second)… */
const PROGRESS_MS = 33;
/** …or between messages carrying an improvement (about one per frame). */
const IMPROVEMENT_MS = 16;

serveLatest((m, { progress }) => {
  let last = -Infinity;
  let points = [];
  let improvement = null;
  let latest = null;
  const flush = () => {
    progress({
      evaluations: latest.evaluations, budget: latest.budget, points,
      improvement: improvement && { ...improvement, scenario: JSON.stringify(improvement.scenario) },
    });
    points = [];
    improvement = null;
    last = performance.now();
  };
  const result = plan_network(m.scenario, m.request, (p) => {
    latest = p;
    if (p.improvement) {
      points.push([p.evaluations, p.improvement.best]);
      improvement = { evaluations: p.evaluations, best: p.improvement.best, scenario: p.improvement.scenario };
    }
    const since = performance.now() - last;
    if (since >= PROGRESS_MS || (improvement && since >= IMPROVEMENT_MS)) flush();
    return true;
  });
  if (latest && (points.length || improvement)) flush();
  return { value: { result } };
});
