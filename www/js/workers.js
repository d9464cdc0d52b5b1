// The page side of a replaceable job worker (worker-loop.js is the other side), the one home of
// "a new edit replaces running work" for the multi-target view and the CRLB map: jobs carry a
// generation; only the newest one matters. When the worker is still busy with an older job
// `staleMs` after that job started, the worker is terminated and a fresh one is started (the
// compiled wasm module is handed over, so that takes milliseconds) and the newest job is posted
// to it. A job's own time is unbounded here: the core bounds its work (named errors).

export class JobWorker {
  /**
   * @param {URL} url - the module worker (built on serveLatest).
   * @param {WebAssembly.Module} module - the page's compiled wasm module.
   * @param {object} o - {onResult(message), onError(message), staleMs}.
   */
  constructor(url, module, { onResult, onError, staleMs }) {
    Object.assign(this, { url, module, onResult, onError, staleMs });
    this.gen = 0; // newest job posted
    this.doneGen = 0; // newest job answered (result or error)
    this.job = null; // the newest job's message
    this.running = null; // {gen, t0}: the job the worker is on
    this.restarts = 0; // workers terminated because they were busy with stale work
    this.timer = null;
    this.spawn();
  }

  spawn() {
    this.worker = new Worker(this.url, { type: 'module' });
    this.worker.onmessage = (e) => this.receive(e.data);
    this.worker.onerror = (e) => this.onError(`worker: ${e.message || 'failed to start'}`);
    this.worker.postMessage({ type: 'init', module: this.module });
  }

  /** Posts a job (an object of cloneable fields); returns its generation. */
  post(job) {
    this.gen += 1;
    this.job = { type: 'job', gen: this.gen, ...job };
    this.worker.postMessage(this.job);
    this.watch();
    return this.gen;
  }

  /** Drops every job: results of older generations are ignored; a running one is terminated. */
  cancel() {
    this.gen += 1;
    this.doneGen = this.gen;
    this.job = null;
    if (this.running) this.restart();
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
    if (m.type === 'ready') return;
    if (m.type === 'start') {
      this.running = { gen: m.gen, t0: performance.now() };
      this.watch();
      return;
    }
    this.running = null;
    if (m.gen < this.doneGen) return; // superseded (or cancelled)
    this.doneGen = m.gen;
    if (m.type === 'error') this.onError(m.message, m.gen);
    else this.onResult(m);
  }

  /** Restarts the worker once its current job is stale and older than staleMs. */
  watch() {
    clearTimeout(this.timer);
    if (!this.running || this.running.gen >= this.gen) return;
    const wait = this.staleMs - this.busyMs();
    if (wait <= 0) this.restart();
    else this.timer = setTimeout(() => this.watch(), wait);
  }

  restart() {
    clearTimeout(this.timer);
    this.worker.terminate();
    this.restarts += 1;
    this.running = null;
    this.spawn();
    if (this.job) this.worker.postMessage(this.job);
  }
}
