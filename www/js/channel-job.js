// The page side of the channel view's worker (channel-worker.js, on workers.js' JobWorker): one
// job at a time; a new start() or simulate() supersedes the running one (its promise rejects
// with a ChannelStopped), stop() drops it (the worker ends it at its next 40 ms slice, or is
// terminated after GRACE_MS). Nothing leaves the machine: the files go to the worker only.
//
//   import { ChannelJobs, ChannelStopped } from './channel-job.js';
//   const jobs = new ChannelJobs(module); // the page's compiled wasm module (optional: compiled here)
//   const r = await jobs.start({ scenario, recording, calibration, truth, targets }, settings,
//     (p) => console.log(p.phase, p.done, p.total));
//   // r: {summary, timings, estimates, track, figure, errors, people (texts; people null
//   //     unless targets: 'auto'), ms (in the worker), wallMs (start() to the result)}
//   const s = await jobs.simulate(scenario, { duration_s: 6, dt_s: 0.02 });
//   // s: {recording: Uint8Array, calibration: Uint8Array, truth, scene (texts), summary}
//   jobs.stop();
//
// `scenario` is the scenario JSON text; `recording`/`calibration` the .npz files' bytes
// (Uint8Array or ArrayBuffer; copied to the worker, never transferred, so the caller keeps them);
// `calibration: null` uses settings.calibration_range_s, or without one a background learnt from
// the recording itself; `truth` the truth file's text or null; `targets` 'one' (the default) or
// 'auto' (several people too: ChannelJob.set_targets); `settings` the core's
// ChannelRequest as an object (its JSON field names: max_paths, pfa, statics, delay_reference, …).
// Errors reject with an Error whose message is the core's named message.

import { JobWorker } from './workers.js';

/** How long a stopped job may take to reach its next pause before the worker is terminated, ms. */
const GRACE_MS = 250;

/** The rejection of a job that was stopped or superseded. */
export class ChannelStopped extends Error {
  constructor() {
    super('stopped');
    this.name = 'ChannelStopped';
  }
}

/** The page's compiled wasm module (for a caller that has none at hand). */
async function compileModule() {
  const url = new URL('../pkg/scatterloc_bg.wasm', import.meta.url);
  return WebAssembly.compile(await (await fetch(url)).arrayBuffer());
}

export class ChannelJobs {
  /** @param {WebAssembly.Module} [module] - the page's compiled wasm module. */
  constructor(module) {
    this.module = module ? Promise.resolve(module) : compileModule();
    this.worker = null;
    this.pending = null; // {gen, resolve, reject, onProgress, t0}
  }

  async ensureWorker() {
    if (this.worker) return this.worker;
    const module = await this.module;
    if (this.worker) return this.worker;
    this.worker = new JobWorker(new URL('./channel-worker.js', import.meta.url), module, {
      staleMs: Infinity, // the worker drops a stopped job at its next slice …
      graceMs: GRACE_MS, // … or is terminated when that takes longer
      onProgress: (m) => {
        const p = this.pending;
        if (p && m.gen === p.gen && p.onProgress) p.onProgress({ phase: m.phase, done: m.done, total: m.total });
      },
      onResult: (m) => this.settle(m.gen, (p) => p.resolve(resultOf(m, p.t0))),
      onError: (message, gen) => {
        const p = this.pending;
        if (!p || (gen !== undefined && gen !== p.gen)) return;
        this.pending = null;
        p.reject(new Error(gen === undefined ? `channel worker: ${message}` : message));
      },
    });
    return this.worker;
  }

  settle(gen, f) {
    const p = this.pending;
    if (!p || p.gen !== gen) return;
    this.pending = null;
    f(p);
  }

  async post(job, onProgress) {
    this.supersede();
    const token = {};
    this.token = token;
    const worker = await this.ensureWorker();
    if (this.token !== token) throw new ChannelStopped(); // stopped or superseded meanwhile
    return new Promise((resolve, reject) => {
      const gen = worker.post(job);
      this.pending = { gen, resolve, reject, onProgress, t0: performance.now() };
    });
  }

  /** Rejects the pending job's promise (it is being replaced or stopped). */
  supersede() {
    this.token = null;
    const p = this.pending;
    this.pending = null;
    if (p) p.reject(new ChannelStopped());
  }

  /**
   * Estimates and tracks a recording: files {scenario, recording, calibration?, truth?, targets?},
   * settings (see the file comment), onProgress({phase, done, total}). Resolves to the result.
   */
  start(files, settings = {}, onProgress = null) {
    return this.post({
      kind: 'run', scenario: files.scenario, recording: files.recording,
      calibration: files.calibration ?? null, truth: files.truth ?? null, targets: files.targets ?? 'one', settings,
    }, onProgress);
  }

  /** Simulates a recording pair (the files of `cir simulate`). */
  simulate(scenario, settings = {}) {
    return this.post({ kind: 'simulate', scenario, settings }, null);
  }

  /** Stops the running job: its promise rejects with a ChannelStopped. */
  stop() {
    this.supersede();
    if (this.worker) this.worker.cancel();
  }

  /** True while a job runs. */
  get busy() {
    return this.pending !== null;
  }
}

/** The page's result object of a worker's result message. */
function resultOf(m, t0) {
  const wallMs = performance.now() - t0;
  if (m.kind === 'simulate') {
    return {
      recording: new Uint8Array(m.recording), calibration: new Uint8Array(m.calibration),
      truth: m.truth, scene: m.scene, summary: m.summary, ms: m.ms, wallMs,
    };
  }
  const { summary, timings, estimates, track, figure, errors, ms } = m;
  return { summary, timings, estimates, track, figure, errors, people: m.people ?? null, ms, wallMs };
}
