// The page side of the page's one job-worker protocol (worker-loop.js is the other side and
// lists the messages), the one home of "a new edit replaces running work" for the CRLB map, the
// multi-target view, the Monte Carlo study and the planner: jobs carry a generation; only the
// newest one matters. A running job becomes stale when a newer job is posted or the jobs are
// cancelled; when the worker is still busy with it `staleMs` after it started, the worker is
// terminated and a fresh one is started (the compiled wasm module is handed over, so that takes
// milliseconds) and the newest job, if any, is posted to it. staleMs: 0 terminates at once (the
// map; the planner, whose wasm call is synchronous); Infinity never does on that ground (the Monte
// Carlo, which pauses between slices and drops a stale job itself). graceMs bounds how long a job
// that went stale may take to reach its next pause (issue 24: one Monte Carlo chunk of a particle
// filter can run for minutes in a single wasm call): past it the worker is terminated too, so Stop
// stops within a fraction of a second. A job's own time is unbounded here: the core bounds its
// work (named errors, the cost prediction of study::cost).

export class JobWorker {
  /**
   * @param {URL} url - the module worker (built on serveLatest).
   * @param {WebAssembly.Module} module - the page's compiled wasm module.
   * @param {object} o - {onResult(message), onProgress?(message), onError(message, gen?),
   *   staleMs, graceMs?, lazy?}: onResult gets every result not older than the last answered job (the
   *   caller may skip those older than `gen`), onProgress the newest job's progress; `lazy`
   *   starts the worker at the first job (and after a termination, at the next one); `graceMs`
   *   (default Infinity) the time a stale job gets to drop itself before the worker is terminated.
   */
  constructor(url, module, { onResult, onProgress = () => {}, onError, staleMs, graceMs = Infinity, lazy = false }) {
    Object.assign(this, { url, module, onResult, onProgress, onError, staleMs, graceMs, lazy });
    this.staleAt = 0; // when the running job became stale (performance.now())
    this.gen = 0; // newest job posted (or cancel)
    this.doneGen = 0; // newest job answered (result or error)
    this.job = null; // the newest job's message
    this.running = null; // {gen, t0}: the job the worker is on
    this.restarts = 0; // workers terminated because they were busy with stale work
    this.ready = false; // the current worker has instantiated the module
    this.timer = null;
    this.worker = null;
    if (!lazy) this.spawn();
  }

  spawn() {
    this.ready = false;
    this.worker = new Worker(this.url, { type: 'module' });
    this.worker.onmessage = (e) => this.receive(e.data);
    this.worker.onerror = (e) => {
      e.preventDefault(); // reported here; the next job starts a fresh worker
      this.drop();
      this.onError(`worker: ${e.message || 'failed to start'}`);
    };
    this.worker.postMessage({ type: 'init', module: this.module });
  }

  /** Posts a job (an object of cloneable fields); returns its generation. */
  post(job) {
    this.gen += 1;
    this.job = { type: 'job', gen: this.gen, ...job };
    this.markStale();
    if (!this.worker) this.spawn();
    this.worker.postMessage(this.job);
    this.watch();
    return this.gen;
  }

  /**
   * Drops every job: results of older generations are ignored; a running one is stale (see the
   * file comment: terminated, or dropped by the worker at its next pause).
   */
  cancel() {
    this.gen += 1;
    this.doneGen = this.gen;
    this.job = null;
    if (this.worker) this.worker.postMessage({ type: 'cancel', gen: this.gen });
    if (!this.running) return;
    this.markStale();
    if (Number.isFinite(this.staleMs) || Number.isFinite(this.graceMs)) this.watch();
    else this.running = null; // it ends at its next pause, without a message
  }

  /** Notes when the running job became stale (the start of its grace period). */
  markStale() {
    if (this.running && !this.staleAt) this.staleAt = performance.now();
  }

  /** True while the newest job has no answer. */
  get pending() {
    return this.doneGen < this.gen;
  }

  /** Milliseconds the current job has been running (0 when idle). */
  busyMs() {
    return this.running ? performance.now() - this.running.t0 : 0;
  }

  receive(m) {
    if (m.type === 'ready') {
      this.ready = true;
      return;
    }
    if (m.type === 'start') {
      this.running = { gen: m.gen, t0: performance.now() };
      this.staleAt = m.gen < this.gen ? performance.now() : 0;
      this.watch();
      return;
    }
    if (m.type === 'dropped') {
      // A stale job ended at its pause: the worker is idle (or on the next job's 'start').
      if (this.running && this.running.gen === m.gen) {
        clearTimeout(this.timer);
        this.running = null;
        this.staleAt = 0;
      }
      return;
    }
    if (m.type === 'progress') {
      if (m.gen === this.gen) this.onProgress(m);
      return;
    }
    this.running = null;
    if (m.gen < this.doneGen) return; // superseded (or cancelled)
    this.doneGen = m.gen;
    if (m.type === 'error') this.onError(m.message, m.gen);
    else this.onResult(m);
  }

  /** Restarts the worker once its current job is stale and older than staleMs, or stale for graceMs. */
  watch() {
    clearTimeout(this.timer);
    if (!this.running || this.running.gen >= this.gen) return;
    const grace = this.staleAt ? this.graceMs - (performance.now() - this.staleAt) : Infinity;
    const wait = Math.min(this.staleMs - this.busyMs(), grace);
    if (!Number.isFinite(wait)) return;
    if (wait <= 0) this.restart();
    else this.timer = setTimeout(() => this.watch(), wait);
  }

  /** Terminates the worker (the next job starts a fresh one). */
  drop() {
    clearTimeout(this.timer);
    this.worker.onmessage = null;
    this.worker.onerror = null;
    this.worker.terminate();
    this.worker = null;
    this.running = null;
    this.staleAt = 0;
  }

  restart() {
    this.drop();
    this.restarts += 1;
    if (this.job || !this.lazy) this.spawn();
    if (this.job) this.worker.postMessage(this.job);
  }
}
