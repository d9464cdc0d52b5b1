// Monte Carlo worker (a module Web Worker, served by worker-loop.js): runs the core's chunked
// study (MonteCarloJob) off the page's main thread (montecarlo.js). Jobs: {gen, scenario, kind,
// x0, y0, vx, vy, dt_s, steps, trajectories, noise_runs, seed, filters ('ekf,ukf,pf' or a part),
// particles, particle_budget}. The study runs in SLICE_MS slices; after each slice it posts
// progress {gen, done, total (chunks), result (MonteCarloJob.result_json text, partial)} and
// pauses, so a newer job or a cancel gets in: then this job is dropped (the page never terminates
// this worker for that, but does when one slice outlasts its 250 ms grace: workers.js graceMs).
// The result: {gen, ms, done, total, result}.

import { MonteCarloJob } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

const SLICE_MS = 40; // work between progress reports and cancellation checks

serveLatest(async (m, { progress, pause }) => {
  const job = new MonteCarloJob(m.scenario, JSON.stringify({
    trajectory: { kind: m.kind, x0_m: m.x0, y0_m: m.y0, vx_mps: m.vx, vy_mps: m.vy },
    dt_s: m.dt_s, steps: m.steps, trajectories: m.trajectories, noise_runs: m.noise_runs, seed: m.seed,
  }));
  try {
    if (m.filters) job.set_filters(m.filters, m.particles, m.particle_budget);
    const report = () => ({ done: job.chunks_done(), total: job.chunk_count(), result: job.result_json() });
    let slice = performance.now();
    while (!job.run_chunks(1)) {
      if (performance.now() - slice >= SLICE_MS) {
        progress(report());
        await pause(); // throws when superseded
        slice = performance.now();
      }
    }
    return { value: report() };
  } finally {
    job.free();
  }
});
