// The page side of the browser Monte Carlo: a job worker (workers.js; mc-worker.js) runs the
// study in slices; a newer generation supersedes a running study (every drag restarts it), which
// the worker drops at its next slice; Stop ends it, its partial result staying on the chart. Shows
// the progress bar, the status line (with the time left, from the measured chunk rate), the status
// bar's read-out and the plotters chart (drawn by the wasm core on #track-chart), all from one
// state of one study: a new study clears the chart at once, so no old curve sits under its status.

import { $, errorText, fitCanvas, fixed } from './dom.js';
import { JobWorker } from './workers.js';

export class MonteCarlo {
  /**
   * @param {object} wasm - the wasm module; @param {WebAssembly.Module} module - its compiled
   * module (handed to the worker); @param {function} onError - shows a message.
   */
  constructor(wasm, module, onError) {
    this.wasm = wasm;
    this.onError = onError;
    this.state = 'idle'; // 'running' | 'done' | 'stopped' | 'error' | 'idle'
    this.params = null;
    this.result = null; // last result JSON text (partial while running)
    this.done = 0;
    this.total = 0;
    this.ms = null; // wall time of the last finished run, ms (post to result)
    this.computeMs = null; // the worker's own time for it
    this.superseded = 0; // running jobs cancelled by a newer one
    this.coldStart = false;
    this.series = 0;
    this.caption = '';
    this.elapsedMs = null; // time from start to the last report, ms
    this.etaMs = null; // time left estimated at the last report, ms (null before the first)
    $('mc-stop').addEventListener('click', () => this.stop());
    this.worker = new JobWorker(new URL('./mc-worker.js', import.meta.url), module, {
      staleMs: Infinity, // the worker drops a stale study at its next slice …
      graceMs: 250, // … or is terminated when that takes longer (one long chunk; issue 24)
      onProgress: (m) => this.receive(m),
      onResult: (m) => this.receive(m),
      onError: (message, gen) => {
        if (gen === undefined) this.fail(`Monte Carlo worker: ${message}`);
        else if (gen === this.gen) this.fail(`Monte Carlo: ${message}`);
      },
    });
    new ResizeObserver(() => this.drawChart()).observe($('track-chart').parentElement);
  }

  /** The generation of the newest study (or cancel). */
  get gen() {
    return this.worker.gen;
  }

  /**
   * Starts a study: {scenario, kind, x0, y0, vx, vy, dt_s, steps, trajectories, noise_runs, seed,
   * filters ('ekf,ukf,pf' or a part), particles, particle_budget}.
   */
  start(params, caption) {
    if (this.state === 'running') this.superseded += 1;
    this.params = params;
    this.caption = caption;
    this.state = 'running';
    this.coldStart = !this.worker.ready; // the time then includes starting the worker's wasm
    this.result = null;
    this.done = 0;
    this.total = 0; // known from the worker's first report
    this.elapsedMs = null;
    this.etaMs = null;
    this.t0 = performance.now();
    this.worker.post(params);
    this.drawChart(); // the new study's empty chart at once
    this.show();
  }

  /** Stop: ends the running study; its partial result stays (chart and figure labelled partial). */
  stop() {
    if (this.state !== 'running') return;
    this.superseded += 1;
    this.worker.cancel();
    this.state = 'stopped';
    this.etaMs = null;
    this.drawChart();
    this.show();
  }

  /** Stops the current study (the worker drops it at its next slice, or is terminated after 250 ms). */
  cancel() {
    if (this.state === 'running') this.superseded += 1;
    this.worker.cancel();
    this.state = 'idle';
    this.show();
  }

  /** A progress or result message of the worker. */
  receive(m) {
    if (m.gen !== this.gen) return; // a superseded or cancelled run
    this.done = m.done;
    this.total = m.total;
    this.result = m.result;
    this.elapsedMs = performance.now() - this.t0;
    // The time left at the rate measured so far (chunks are of one size).
    this.etaMs = m.done > 0 ? (this.elapsedMs * (m.total - m.done)) / m.done : null;
    if (m.type === 'result') {
      this.state = 'done';
      this.ms = this.elapsedMs;
      this.etaMs = null;
      this.computeMs = m.ms;
    }
    this.drawChart();
    this.show();
  }

  fail(message) {
    this.state = 'error';
    this.show();
    this.onError(message);
    console.error(message);
  }

  /** The chart at the canvas' CSS size times the device pixel ratio. */
  drawChart() {
    const canvas = $('track-chart');
    const r = canvas.getBoundingClientRect();
    if (r.width < 10 || r.height < 10) return;
    fitCanvas(canvas); // the chart fills its background itself
    const t = this.chartText();
    try {
      this.series = this.wasm.draw_tracking_chart(canvas, this.result || '', t.title, t.subtitle, t.caption);
    } catch (e) {
      this.series = 0;
      this.onError(`Chart: ${errorText(e)}`);
      console.error(e);
    }
    // The study drawn: its generation and chunk counts, as the status line's.
    Object.assign(canvas.dataset, {
      series: String(this.series), generation: String(this.gen), state: this.state,
      done: String(this.done), total: String(this.total), title: t.title, subtitle: t.subtitle,
    });
  }

  /** The chart's {title, subtitle, caption} (the canvas and the SVG of "Save figure" share them). */
  chartText() {
    const p = this.params;
    const r = this.result ? JSON.parse(this.result) : null;
    let sub = p ? `${p.trajectories * p.noise_runs} runs × ${p.steps} steps, T = ${p.dt_s} s` : '';
    if (r) sub += ` · ${failedRuns(r)}`;
    if (this.state === 'running') sub += ` · ${this.progressText()}`;
    if (this.state === 'stopped') sub += ` · ${this.stoppedText()}`;
    const names = p && p.filters ? p.filters.toUpperCase().split(',').join(', ') : 'EKF';
    // A study still running (or stopped) labels its figure, the canvas and a saved file alike.
    const partial = r && !r.done ? partialRuns(r, names.includes(',')) : '';
    const title = `Position RMSE: ${names} vs posterior CRLB${partial ? ` (${partial})` : ''}`;
    return { title, subtitle: sub, caption: this.caption, partial };
  }

  /** A running study's progress: "starting…" before the first report, then "running 55/1251 chunks". */
  progressText() {
    return this.total ? `running ${this.done}/${this.total} chunks` : 'starting…';
  }

  /** A stopped study's progress: "stopped at 55/1251 chunks". */
  stoppedText() {
    return this.total ? `stopped at ${this.done}/${this.total} chunks` : 'stopped before its first report';
  }

  /** The time left of a running study, "about 12 s left" (from the measured chunk rate), or ''. */
  etaText() {
    if (this.state !== 'running' || this.etaMs === null) return '';
    const s = Math.round(this.etaMs / 1000);
    return `about ${s < 60 ? `${s} s` : `${Math.floor(s / 60)} min ${s % 60} s`} left`;
  }

  /**
   * Progress bar, status line, Stop and the status bar's read-out (numbers and labels from the
   * result), all of the current study.
   */
  show() {
    const el = $('mc-status');
    Object.assign(el.dataset, {
      state: this.state, generation: String(this.gen), done: String(this.done),
      total: String(this.total), ms: this.ms === null ? '' : String(this.ms),
      eta: this.etaMs === null ? '' : String(this.etaMs),
    });
    $('mc-bar').style.width = `${this.total ? (100 * this.done) / this.total : 0}%`;
    $('mc-bar').classList.toggle('running', this.state === 'running');
    $('mc-stop').disabled = this.state !== 'running';
    const p = this.params;
    const size = p ? `${p.trajectories * p.noise_runs} runs × ${p.steps} steps` : '';
    const eta = this.etaText();
    let text = size;
    if (this.state === 'running') text = `${size} · ${this.progressText()}${eta ? ` · ${eta}` : ''}`;
    if (this.state === 'stopped') text = `${size} · ${this.stoppedText()} (the chart shows the runs done)`;
    const r = this.result ? JSON.parse(this.result) : null;
    if (this.state === 'done' && r) {
      const n = r.t_s.length - 1;
      const fmt = (v) => (v === null || v === undefined ? '—' : this.wasm.format_length(v, 3));
      const cold = this.coldStart ? ' (incl. worker start-up)' : '';
      const each = Object.entries(r.filters).map(([name, f]) => `ε_${name.toUpperCase()} ${fmt(f.rmse_m[n])}`
        + ` (NEES ${fixed(f.nees[n], 2)})`).join(', ');
      text = `${size} in ${fixed(this.ms, 0)} ms${cold} · at t = ${r.t_s[n]} s: ${each}, `
        + `ε_PCRLB ${fmt(r.rmse_pcrlb_m[n])} · NEES 4 = consistent · ${failedRuns(r)}`;
    }
    const pf = r && r.filters.pf;
    $('mc-pf-note').textContent = pf ? `PF: ${pf.runs_planned} runs × ${r.particles} particles, `
      + `${pf.failed_runs} of ${pf.runs + pf.failed_runs} failed (page budget ${r.particle_budget / 1e6}·10⁶ particle-steps)` : '';
    if (this.state === 'error') text = `${size} · failed`;
    el.textContent = text;
    el.title = FAILED_MEANING;
    // The status bar: the same study, never the time of an earlier one under this one's size.
    const ms = $('mc-ms');
    const bar = {
      running: `MC ${size}: ${this.progressText()}${eta ? `, ${eta}` : ''}`,
      done: `MC ${size}: ${fixed(this.ms, 0)} ms`,
      stopped: `MC ${size}: ${this.stoppedText()}`,
      error: `MC ${size}: failed`,
    }[this.state];
    ms.textContent = bar || 'MC –';
    Object.assign(ms.dataset, {
      ms: this.state === 'done' ? String(this.ms) : '', generation: String(this.gen), state: this.state,
      done: String(this.done), total: String(this.total),
    });
  }
}

/**
 * The failed-run counts of a result, shown wherever the RMSE is (even when 0): "0 failed runs",
 * "EKF 0, PF 3 failed runs (the filter broke down numerically: excluded from the RMSE)"; a filter that failed in every run
 * (`failed_filters`, issue 24) adds its error, e.g. " · PF: particles: every run of the PF failed …".
 */
function failedRuns(r) {
  const f = Object.entries(r.filters || { ekf: r });
  const total = f.reduce((a, [, c]) => a + c.failed_runs, 0);
  const counts = f.length === 1 ? String(total) : f.map(([name, c]) => `${name.toUpperCase()} ${c.failed_runs}`).join(', ');
  const all = (r.failed_filters || []).map((x) => ` · ${x.name.toUpperCase()}: ${x.error}`).join('');
  return `${counts} failed run${total === 1 && f.length === 1 ? '' : 's'}${total ? ' (the filter broke down numerically: excluded from the RMSE)' : ''}${all}`;
}

/**
 * The runs counted so far of a result still in progress, per filter against the runs it will
 * make: "partial: 64 of 200 runs", or with `several` filters in the study (those counted so far)
 * "partial: EKF 200 of 200, PF 16 of 192 runs".
 */
export function partialRuns(r, several) {
  const f = Object.entries(r.filters || {});
  if (!f.length) return `partial: ${r.runs + r.failed_runs} of ${r.trajectories * r.noise_runs} runs`;
  const each = f.map(([name, c]) => [name.toUpperCase(), c.runs + c.failed_runs, c.runs_planned]);
  if (!several) return `partial: ${each[0][1]} of ${each[0][2]} runs`;
  return `partial: ${each.map(([n, d, t]) => `${n} ${d} of ${t}`).join(', ')} runs`;
}

/** What a failed run is (the chart's legend says the same, from the core). */
export const FAILED_MEANING = 'a failed run: the filter broke down numerically (its covariance stopped '
  + 'being positive definite, e.g. the particles collapsed onto one), so it is left out of the RMSE';
