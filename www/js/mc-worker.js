// Monte Carlo worker (a module Web Worker): runs the core's chunked study (MonteCarloJob) off the
// page's main thread. Messages in: {type: 'run', gen, scenario, kind, x0, y0, vx, vy, dt_s, steps,
// trajectories, noise_runs, seed, filters ('ekf,ukf,pf' or a part), particles, particle_budget}
// or {type: 'cancel', gen}. A newer generation cancels the job in
// progress at its next slice boundary. Messages out: {type: 'progress' | 'done', gen, done, total,
// result (MonteCarloJob.result_json text), ms}, {type: 'error', gen, message} and, once the wasm
// module is compiled, {type: 'ready'}.

import init, { MonteCarloJob } from '../pkg/scatterloc.js';
import { errorText } from './dom.js';

const SLICE_MS = 40; // work between progress reports and cancellation checks
const ready = init().then(() => self.postMessage({ type: 'ready' }));
let current = -1;

self.onmessage = (e) => {
  const m = e.data;
  current = m.gen;
  if (m.type === 'run') {
    run(m).catch((err) => self.postMessage({ type: 'error', gen: m.gen, message: errorText(err) }));
  }
};

/** Lets queued messages (a newer job) in. */
const pause = () => new Promise((resolve) => setTimeout(resolve, 0));

async function run(m) {
  await ready;
  if (m.gen !== current) return;
  const t0 = performance.now();
  const job = new MonteCarloJob(m.scenario, m.kind, m.x0, m.y0, m.vx, m.vy, m.dt_s, m.steps,
    m.trajectories, m.noise_runs, m.seed);
  try {
    if (m.filters) job.set_filters(m.filters, m.particles, m.particle_budget);
    const report = (type) => self.postMessage({
      type, gen: m.gen, done: job.chunks_done(), total: job.chunk_count(),
      result: job.result_json(), ms: performance.now() - t0,
    });
    let slice = performance.now();
    while (!job.run_chunks(1)) {
      if (performance.now() - slice >= SLICE_MS) {
        report('progress');
        await pause();
        if (m.gen !== current) return; // superseded
        slice = performance.now();
      }
    }
    report('done');
  } finally {
    job.free();
  }
}
