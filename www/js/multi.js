// Several people in the tracking view (issue 41 §2): the panel's "Several people" block (walkers
// off, 1–5 on the planned paths, or "drawn": one walker per path drawn on the map, press = start,
// release = where it is after the run's 10 s, up to MAX_PATHS, a further one replacing the
// oldest; "Clear drawn paths" returns to the plans), the method PMB or GNN), the run in a Web Worker (multi-worker.js: the core's
// track_people simulates the walkers, tracks their delay scans and scores the track, as the CLI's
// simulate-walk --walkers then track --targets auto --truth), the map layer (every true path
// thin, every labelled track in its own colour with its label and its current 1σ ellipse) and
// the GOSPA chart (the core's curve figure, draw_people_chart). tracking.js owns the animation
// step and asks this file what to draw at it; "off" leaves the single-target view as it was.

import { $, errorText, fitCanvas, fixed } from './dom.js';
import { drawPeople, peopleColour, peopleTruthPaths } from './people-draw.js';
import { drawPathArrows } from './track-draw.js';
import { JobWorker } from './workers.js';

/** The most drawn paths (the core's MAX_WALKERS); a further press replaces the oldest. */
export const MAX_PATHS = 5;
/** The walkers select's value of the drawn paths. */
export const DRAWN = 'drawn';

export class Multi {
  /**
   * @param {object} ctx - app.js ctx (module, wasm); @param {object} o - {onResult() (a new
   * document arrived), onError(message)}.
   */
  constructor(ctx, { onResult, onError }) {
    this.ctx = ctx;
    this.onResult = onResult;
    this.onError = onError;
    this.state = 'off'; // 'running' | 'done' | 'stopped' | 'error' | 'off'
    this.params = null;
    this.text = null; // the last document's JSON text
    this.doc = null; // … parsed
    this.ms = null; // post to result, ms (the page's timer)
    this.computeMs = null; // the worker's own time for it
    this.error = null;
    this.superseded = 0; // running jobs replaced by a newer one or cancelled
    this.series = 0; // GOSPA points the chart drew
    this.layer = null; // what the map layer drew last
    this.paths = []; // the drawn walker paths, {x0, y0, x1, y1} m, oldest first
    this.pathDrag = null; // the path being drawn (press to release), or null
    this.plans = '2'; // the walkers count "Clear drawn paths" returns to (the last one chosen)
    this.worker = new JobWorker(new URL('./multi-worker.js', import.meta.url), ctx.module, {
      staleMs: 0, // one synchronous wasm call: a newer job or Stop terminates the worker
      lazy: true,
      onResult: (m) => this.receive(m),
      onError: (message, gen) => {
        if (gen === undefined || gen === this.worker.gen) this.fail(`Several people: ${message}`);
      },
    });
    $('multi-stop').addEventListener('click', () => this.stop());
    new ResizeObserver(() => this.drawChart()).observe($('multi-chart').parentElement);
  }

  /** Whether the block is on (walkers chosen, not "off"). */
  get on() { return $('multi-walkers').value !== 'off'; }

  /** Whether the walkers are the drawn paths (the select's "drawn"): a press-drag on the map adds one. */
  get drawing() { return $('multi-walkers').value === DRAWN; }

  /** The walkers of a run: the drawn paths' count, or the select's number. */
  walkers() { return this.drawing ? this.paths.length : Number($('multi-walkers').value); }

  /** The drawn paths as the core takes them, [[x0, y0, x1, y1], …]. */
  pathRows() { return this.paths.map((p) => [p.x0, p.y0, p.x1, p.y1]); }

  /** The walkers select changed: a count is remembered as the plans "Clear drawn paths" returns to. */
  walkersChosen() {
    const v = $('multi-walkers').value;
    if (v !== 'off' && v !== DRAWN) this.plans = v;
    this.showPaths();
  }

  /** A press on the map (draw mode, m): a new path starts there. */
  pathStart(m) { this.pathDrag = { x0: m.x, y0: m.y, x1: m.x, y1: m.y }; }

  /** The drag moved (m): the new path's end follows. */
  pathMove(m) { if (this.pathDrag) this.pathDrag = { ...this.pathDrag, x1: m.x, y1: m.y }; }

  /**
   * The press ended at `m` (m): the path is added (the oldest dropped past MAX_PATHS); a press
   * without a drag adds nothing. Returns whether the paths changed (a run is due).
   */
  pathEnd(m) {
    this.pathMove(m);
    const p = this.pathDrag;
    this.pathDrag = null;
    if (!p || (p.x0 === p.x1 && p.y0 === p.y1)) return false;
    this.paths = [...this.paths, p].slice(-MAX_PATHS);
    this.showPaths();
    return true;
  }

  /** "Clear drawn paths": none left, and the walkers back on the plans (the last count chosen). */
  clearPaths() {
    this.paths = [];
    this.pathDrag = null;
    if (this.drawing) $('multi-walkers').value = this.plans;
    this.showPaths();
  }

  /** The select's "drawn" option and the Clear button show the drawn paths' count. */
  showPaths() {
    const n = this.paths.length;
    const o = $('multi-walkers').querySelector(`option[value="${DRAWN}"]`);
    if (o) o.textContent = n ? `drawn (${n})` : 'drawn…';
    $('multi-clear').disabled = n === 0;
    $('multi-hint').hidden = !this.drawing;
  }

  /** "drawn" with no path yet: nothing runs; the status asks for a path. */
  waitForPaths() {
    if (this.state === 'running') this.superseded += 1;
    this.worker.cancel();
    this.params = null;
    this.text = null;
    this.doc = null;
    this.state = 'draw';
    this.drawChart();
    this.show();
  }

  /** The number of scans of the document shown (0 without one). */
  entries() { return this.doc ? this.doc.track.t_s.length : 0; }

  /** Starts a run: {scenario (JSON text), walkers, paths? ([[x0, y0, x1, y1], …] m), method, seed}. */
  start(params) {
    if (this.state === 'running') this.superseded += 1;
    this.params = params;
    this.state = 'running';
    this.error = null;
    // A new run clears the old one at once (map, chart, read-out): no old track under its status.
    this.text = null;
    this.doc = null;
    this.t0 = performance.now();
    this.worker.post(params);
    this.drawChart();
    this.show();
  }

  /** Stop: the running job's worker is terminated (nothing is shown until the next run). */
  stop() {
    if (this.state !== 'running') return;
    this.superseded += 1;
    this.worker.cancel();
    this.state = 'stopped';
    this.show();
  }

  /** Off (or leaving the view): drops any job. */
  cancel() {
    if (this.state === 'running') this.superseded += 1;
    this.worker.cancel();
    this.state = this.on ? 'stopped' : 'off';
    this.show();
  }

  receive(m) {
    if (m.gen !== this.worker.gen) return;
    this.ms = performance.now() - this.t0;
    this.computeMs = m.ms;
    this.text = m.text;
    this.doc = JSON.parse(m.text);
    this.state = 'done';
    this.drawChart();
    this.show();
    this.onResult();
  }

  fail(message) {
    this.state = 'error';
    this.error = message;
    this.show();
    this.onError(message);
  }

  /** The GOSPA chart at the canvas' CSS size times the device pixel ratio. */
  drawChart() {
    const canvas = $('multi-chart');
    const r = canvas.getBoundingClientRect();
    if (r.width < 10 || r.height < 10) return;
    fitCanvas(canvas);
    const d = this.doc;
    const title = 'GOSPA per scan';
    const sub = d ? `${d.walkers} walkers, ${d.track.method.toUpperCase()}, seed ${d.seed}, `
      + `${d.track.t_s.length} scans of ${d.dt_s} s` : '';
    try {
      this.series = this.ctx.wasm.draw_people_chart(canvas, this.text || '', title, sub);
    } catch (e) {
      this.series = 0;
      this.onError(`GOSPA chart: ${errorText(e)}`);
    }
    Object.assign(canvas.dataset, { series: String(this.series), title, subtitle: sub });
  }

  /** The status line and Stop. */
  show() {
    const el = $('multi-status');
    const p = this.params;
    const who = p && p.paths ? `${p.walkers} drawn path${p.walkers === 1 ? '' : 's'}`
      : p ? `${p.walkers} walker${p.walkers === 1 ? '' : 's'}` : '';
    const what = p ? `${who} · ${p.method.toUpperCase()}` : '';
    const d = this.doc;
    let text = {
      off: 'off: the single-target view',
      running: `${what} · running…`,
      stopped: `${what} · stopped (change a setting to run again)`,
      error: `${what} · failed`,
      draw: `drawn: press on the map at a walker's start and drag to where it is after 10 s (up to ${MAX_PATHS})`,
    }[this.state] || '';
    if (this.state === 'done' && d) {
      const s = d.score;
      const n = d.track.t_s.length;
      text = `${what} · ${n} scans in ${fixed(this.ms, 0)} ms (worker ${fixed(this.computeMs, 0)} ms; `
        + `tracking ${fixed(d.timing_ms.scans / n, 2)} ms per scan after a ${fixed(d.timing_ms.setup, 0)} ms setup)`
        + ` · mean GOSPA ${this.ctx.wasm.format_length(s.mean_gospa_m, 3)}, ${s.switches} label switch`
        + `${s.switches === 1 ? '' : 'es'}, cardinality error ${fixed(s.mean_cardinality_error, 2)}`;
    }
    el.textContent = text;
    Object.assign(el.dataset, {
      state: this.state, generation: String(this.worker.gen), ms: this.ms === null ? '' : String(this.ms),
    });
    $('multi-stop').disabled = this.state !== 'running';
  }

  /** The scan's time, s. */
  timeAt(step) { return this.doc ? this.doc.track.t_s[step] : 0; }

  /** The read-out rows at scan `step`: each reported target, then the GOSPA. */
  rows(step) {
    const d = this.doc;
    if (!d) return [];
    const len = (v) => this.ctx.wasm.format_length(v, 3);
    const rows = d.track.targets[step].map((t, i) => {
      const e = d.ellipses[step][i];
      return [`Track ${t.label}`, `${fixed(t.state[0], 3)}, ${fixed(t.state[1], 3)} m · 1σ ${e ? len(e.a) : '–'}`, ''];
    });
    rows.push(['True people', String(d.truth.targets[step].length), '']);
    rows.push([`GOSPA (c = ${len(d.score.c_m)})`, len(d.score.gospa_m[step]), '']);
    return rows;
  }

  /** The colour of the track with `label`: its place among the document's tracks (label order). */
  colour(label) { return peopleColour(this.doc, label); }

  /** Every true path, [[x, y], …] per person (label order). */
  truthPaths() { return peopleTruthPaths(this.doc); }

  /**
   * The map layer at scan `step` (ellipses magnified by `magnify`): the drawn paths, then the
   * people (people-draw.js: true paths thin, each track up to the step in its colour with its
   * label and current 1σ ellipse). Returns what was drawn: {step, truth: [[x, y]…] per person,
   * tracks: [{label, colour, state, ellipse, points}], paths}.
   */
  draw(ctx, view, step, magnify) {
    const d = this.doc;
    this.layer = { step, truth: [], tracks: [], paths: [] };
    // The drawn paths (and the one being drawn) as arrows, under the tracks.
    if (this.drawing) {
      const shown = this.pathDrag ? [...this.paths, this.pathDrag] : this.paths;
      this.layer.paths = drawPathArrows(ctx, view, shown);
    }
    if (!d) return this.layer;
    this.layer = { ...drawPeople(ctx, view, d, step, magnify, (label) => this.colour(label)), paths: this.layer.paths };
    return this.layer;
  }

  /** Points the zoom inset should not hide: the true paths, the drawn paths' ends. */
  avoidPoints() {
    const pts = this.doc ? this.truthPaths().flat().map((p) => [p[0], p[1], 10]) : [];
    if (this.drawing) for (const p of this.paths) pts.push([p.x0, p.y0, 10], [p.x1, p.y1, 10]);
    return pts;
  }

  /** Test and console hook (the document itself as `doc`): tracking.js state().multi. */
  snapshot() {
    return {
      on: this.on, walkers: $('multi-walkers').value, method: $('multi-method').value, state: this.state,
      generation: this.worker.gen, ms: this.ms, computeMs: this.computeMs, superseded: this.superseded,
      restarts: this.worker.restarts, error: this.error, scans: this.entries(), series: this.series,
      params: this.params ? { walkers: this.params.walkers, method: this.params.method, seed: this.params.seed,
        ...(this.params.paths ? { paths: this.params.paths } : {}) } : null,
      paths: this.pathRows(), drawing: this.drawing,
      doc: this.doc, layer: this.layer,
    };
  }
}
