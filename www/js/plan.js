// The Plan panel of the snapshot view: moves nodes so that the CRLB over a region of interest
// (ROI) improves, with the core's planner (plan_network: CMA-ES on a coarse ROI grid, re-scored
// on the requested grid) in a job worker (workers.js, plan-worker.js). While it runs, every
// improvement is applied to the page's App and the nodes glide to it (GLIDE_MS, one map per
// frame at a drag's cost); a small chart shows the objective against evaluations. At the end the objective before
// → after (plan.json, requested grid) is shown and its scenario applied. Stop, a node drag, any
// scenario edit (preset, import, inputs) or leaving the snapshot view cancels the plan (the
// worker is terminated); Undo restores the whole scenario saved at Optimize.
//
// The ROI is the whole scenario area unless one is drawn ("Draw ROI", then a drag on the map;
// interact.js routes the pointer here). It is drawn dashed over the map while the panel is open.

import { $, clearError, decimalIn, errorText, fitCanvas, fixed, showError } from './dom.js';
import { C, FONT } from './draw.js';
import { JobWorker } from './workers.js';
import { registerSection } from './state.js';
import { choice, fields, inputNumber, number, rect } from './state-fields.js';

/** Duration of a node glide to an improved layout, ms. */
const GLIDE_MS = 200;
/** A drag shorter than this (CSS px, either side) draws no ROI. */
const ROI_MIN_PX = 4;
const ROI_COLOR = '#ffd166';

/** Inputs of the panel: the name in messages and the allowed range (dom.js decimalIn). */
export const FIELDS = {
  // min, max: the core's (MAX_PLAN_BUDGET), from plan_field_ranges in the constructor.
  'plan-budget': { name: 'plan budget', integer: true, unit: 'evaluations' },
  'plan-seed': { name: 'plan seed', min: 0, max: Number.MAX_SAFE_INTEGER, integer: true },
  'plan-t': { name: 'plan coverage threshold T', min: 0.000001, max: 100000000, unit: 'm' },
};

const smooth = (f) => f * f * (3 - 2 * f);

/** `a` → `b` at fraction t ∈ [0, 1), kept between the two (rounding never overshoots). */
function mix(a, b, t) {
  const v = a + (b - a) * t;
  return Math.min(Math.max(v, Math.min(a, b)), Math.max(a, b));
}

/**
 * The scenario object `to` with each node that `from` also has (same index and name) moved the
 * fraction t of the way from its place in `from` (positions, and beam boresights).
 */
function between(from, to, t) {
  const out = structuredClone(to);
  const move = (list, old = []) => list.forEach((n, i) => {
    const o = old[i];
    if (!o || o.name !== n.name) return;
    n.position_m = [mix(o.position_m[0], n.position_m[0], t), mix(o.position_m[1], n.position_m[1], t)];
    if (n.pattern?.kind === 'parabolic' && o.pattern?.kind === 'parabolic') {
      n.pattern.boresight_deg = mix(o.pattern.boresight_deg, n.pattern.boresight_deg, t);
    }
  });
  move(out.transmitters, from.transmitters);
  move(out.receivers, from.receivers);
  return out;
}

/**
 * True when scenario objects `a` and `b` place every node alike (positions and beam boresights):
 * the planner handed back the layout it started from.
 */
function sameLayout(a, b) {
  const same = (x, y) => x.length === y.length && x.every((n, i) => n.position_m[0] === y[i].position_m[0]
    && n.position_m[1] === y[i].position_m[1] && (n.pattern?.boresight_deg ?? null) === (y[i].pattern?.boresight_deg ?? null));
  return same(a.transmitters, b.transmitters) && same(a.receivers, b.receivers);
}

/**
 * True when plan.json's objective `o` is better after than before as the panel reports it: fewer
 * unbounded cells, else a lower value (a higher one for coverage). A layout the planner ranks
 * better only by a tie-break the panel does not show (0 % → 0 %) is not.
 */
function improved(o) {
  if (o.unbounded_after !== o.unbounded_before) return o.unbounded_after < o.unbounded_before;
  if (o.before === null || o.after === null) return o.before === null && o.after !== null;
  return o.maximised ? o.after > o.before : o.after < o.before;
}

export class Plan {
  /** @param {object} ctx - {app, wasm, module, st, view, changed, showHint}. */
  constructor(ctx) {
    this.ctx = ctx;
    // The budget's range and default come from the core (one definition).
    const ranges = JSON.parse(ctx.wasm.plan_field_ranges());
    [FIELDS['plan-budget'].min, FIELDS['plan-budget'].max] = ranges.budget;
    this.defaultBudget = ranges.default_budget; // DEFAULT_PLAN_BUDGET
    this.status = 'idle'; // 'idle' | 'running' | 'done' | 'error'
    // Started at the first plan; staleMs 0: a cancelled plan's worker is terminated at once (its
    // wasm call is synchronous) and the next plan starts a fresh one.
    this.worker = new JobWorker(new URL('./plan-worker.js', import.meta.url), ctx.module, {
      staleMs: 0,
      lazy: true,
      onProgress: (m) => this.progress(m),
      onResult: (m) => this.finish(m),
      onError: (message, gen) => {
        if (gen === undefined || this.current({ gen })) this.fail(message); // undefined: the worker's own
      },
    });
    this.run = null; // the current or last plan: {id (its job's gen), request, t0, evaluations, …}
    this.points = []; // the chart's [evaluations, best]
    this.chartPoints = 0; // finite points in the last chart drawn
    this.result = null; // the last plan.json
    this.undoJson = null; // the scenario saved at Optimize
    this.undoPreset = '';
    this.applied = null; // the last layout fully applied (JSON text)
    this.roi = null; // [x0, x1, y0, y1] m, or null: the whole area
    this.drawing = false; // "Draw ROI" armed
    this.sketch = null; // the ROI being drawn: {a, b} (CSS px)
    this.glide = null;
    this.frame = 0;
    this.open = false;
    this.error = null;

    $('plan-toggle').addEventListener('click', () => this.setOpen(!this.open));
    $('plan-objective').addEventListener('change', () => this.sync());
    for (const id of Object.keys(FIELDS)) {
      const el = $(id);
      el.setAttribute('inputmode', 'decimal');
      el.setAttribute('autocomplete', 'off');
      el.setAttribute('spellcheck', 'false');
      el.addEventListener('change', () => {
        try {
          this.field(id);
          clearError();
        } catch (e) {
          showError(errorText(e));
        }
      });
    }
    $('plan-run').addEventListener('click', () => this.start());
    $('plan-stop').addEventListener('click', () => this.stop());
    $('plan-undo').addEventListener('click', () => this.undo());
    $('plan-roi-draw').addEventListener('click', () => this.arm(!this.drawing));
    $('plan-roi-reset').addEventListener('click', () => this.setRoi(null));
    new ResizeObserver(() => this.drawChart()).observe($('plan-chart').parentElement);
    this.sync();
  }

  // ---------- inputs ----------

  /** The number in input `id`, strictly parsed and range-checked (FIELDS); marks it invalid on error. */
  field(id) {
    const f = FIELDS[id];
    try {
      const v = decimalIn($(id).value, f.name, f);
      $(id).classList.remove('invalid');
      return v;
    } catch (e) {
      $(id).classList.add('invalid');
      throw e;
    }
  }

  /** The request of the panel's inputs (plan_network's request object); throws on a bad input. */
  request() {
    const kind = $('plan-objective').value;
    return {
      move: $('plan-move').value,
      objective: kind === 'coverage' ? `coverage:${this.field('plan-t')}` : kind,
      roi: this.roiArea(),
      grid: Number($('plan-grid').value),
      budget: this.field('plan-budget'),
      seed: this.field('plan-seed'),
    };
  }

  setOpen(on) {
    this.open = !!on;
    $('plan-body').hidden = !this.open;
    $('plan-toggle').setAttribute('aria-expanded', String(this.open));
    $('plan-toggle').textContent = this.open ? 'Hide' : 'Show';
    if (!this.open) this.arm(false);
    this.sync();
    this.drawChart();
    this.ctx.changed({ draw: true });
  }

  // ---------- the region of interest ----------

  /** The ROI the next plan uses, [x0, x1, y0, y1] m. */
  roiArea() {
    return this.roi ? [...this.roi] : Array.from(this.ctx.app.area());
  }

  /**
   * Throws unless `r` is a rectangle the planner accepts (the core's rule for areas: a span of at
   * least its minimum, check_rect) inside the scenario area (or `area`, [x0, x1, y0, y1] m).
   */
  checkRoi(r, area = null) {
    const [ax0, ax1, ay0, ay1] = Array.from(area ?? this.ctx.app.area());
    const text = `[${r.join(', ')}]`;
    if (!(r.length === 4 && r.every(Number.isFinite))) throw new Error(`${text} is not 4 finite numbers x0, x1, y0, y1`);
    if (!(r[0] < r[1] && r[2] < r[3])) throw new Error(`${text} is empty (x0 < x1 and y0 < y1 are needed)`);
    this.ctx.wasm.check_rect('roi', ...r); // the core's rule for areas (the planner's too): its smallest span
    if (r[0] < ax0 || r[1] > ax1 || r[2] < ay0 || r[3] > ay1) {
      throw new Error(`${text} m must lie inside the scenario area [${ax0}, ${ax1}, ${ay0}, ${ay1}] m`);
    }
  }

  /** Sets the ROI ([x0, x1, y0, y1] m; null: the whole area); a bad one throws and changes nothing. */
  setRoi(r) {
    if (r !== null) {
      r = Array.from(r);
      this.checkRoi(r);
    }
    this.roi = r;
    this.sync();
    this.ctx.changed({ draw: true });
  }

  /** The scenario was replaced (preset, import): an ROI outside its area becomes the whole area. */
  onReset() {
    this.cancel('scenario change');
    this.undoJson = null;
    if (this.roi) {
      try {
        this.checkRoi(this.roi);
      } catch (_) {
        this.roi = null;
      }
    }
    this.sync();
  }

  /** Arms (or disarms) "Draw ROI": the next drag on the map draws the ROI. */
  arm(on) {
    this.drawing = !!on && this.ctx.st.mode === 'snapshot';
    if (this.drawing && !this.open) this.setOpen(true);
    this.sketch = null;
    this.sync();
    if (this.ctx.showHint) this.ctx.showHint();
    this.ctx.changed({ draw: true });
  }

  /** True when a press on the map should draw the ROI (interact.js). */
  wantsRoi() {
    return this.drawing && this.ctx.st.mode === 'snapshot';
  }

  roiStart(p) {
    this.sketch = { a: p, b: p };
    this.ctx.changed({ draw: true });
  }

  roiMove(p) {
    if (this.sketch) this.sketch.b = p;
    this.ctx.changed({ draw: true });
  }

  /** Ends the ROI drag at CSS pixel `p`; `commit` false (pointer cancelled) keeps the old ROI. */
  roiEnd(p, commit) {
    const s = this.sketch;
    this.sketch = null;
    this.drawing = false;
    if (s && commit && Math.abs(p.x - s.a.x) >= ROI_MIN_PX && Math.abs(p.y - s.a.y) >= ROI_MIN_PX) {
      const { view, app } = this.ctx;
      const r = view.rect;
      const lo = { x: r.x, y: r.y };
      const hi = { x: r.x + r.w, y: r.y + r.h };
      const a = view.toMetreWithin(s.a, lo, hi);
      const b = view.toMetreWithin(p, lo, hi);
      const [ax0, ax1, ay0, ay1] = Array.from(app.area());
      const clamp = (v, l, h) => Math.min(Math.max(v, l), h);
      const roi = [
        clamp(Math.min(a.x, b.x), ax0, ax1), clamp(Math.max(a.x, b.x), ax0, ax1),
        clamp(Math.min(a.y, b.y), ay0, ay1), clamp(Math.max(a.y, b.y), ay0, ay1),
      ];
      try {
        this.setRoi(roi);
      } catch (e) {
        showError(`ROI: ${errorText(e)}`);
      }
    }
    this.sync();
    if (this.ctx.showHint) this.ctx.showHint();
    this.ctx.changed({ draw: true });
  }

  /** True when the ROI is drawn over the map: the panel is open or a plan runs (snapshot view). */
  showsRoi() {
    return this.ctx.st.mode === 'snapshot' && (this.open || this.status === 'running' || this.drawing);
  }

  /** Draws the ROI (dashed, the outside dimmed) or the one being drawn on the map canvas. */
  overlay(g, view) {
    let box;
    if (this.sketch) {
      const r = view.rect;
      const c = (p) => ({
        x: Math.min(Math.max(p.x, r.x), r.x + r.w),
        y: Math.min(Math.max(p.y, r.y), r.y + r.h),
      });
      const a = c(this.sketch.a);
      const b = c(this.sketch.b);
      box = { x: Math.min(a.x, b.x), y: Math.min(a.y, b.y), w: Math.abs(b.x - a.x), h: Math.abs(b.y - a.y) };
    } else {
      const [x0, x1, y0, y1] = this.roiArea();
      const a = view.toPixel(x0, y1);
      const b = view.toPixel(x1, y0);
      box = { x: a.x, y: a.y, w: b.x - a.x, h: b.y - a.y };
    }
    const r = view.rect;
    g.save();
    if (this.roi || this.sketch) {
      g.beginPath();
      g.rect(r.x, r.y, r.w, r.h);
      g.rect(box.x, box.y, box.w, box.h);
      g.fillStyle = 'rgba(8, 10, 16, 0.35)';
      g.fill('evenodd');
    }
    g.setLineDash([7, 5]);
    g.lineWidth = 1.5;
    g.strokeStyle = ROI_COLOR;
    g.strokeRect(box.x, box.y, box.w, box.h);
    g.setLineDash([]);
    g.font = FONT;
    g.fillStyle = ROI_COLOR;
    g.textAlign = 'left';
    g.textBaseline = 'top';
    g.fillText('ROI', box.x + 5, box.y + 4);
    g.restore();
  }

  // ---------- running ----------

  /**
   * Optimize: plans the panel's request (fields of `overrides` replace its fields) on the
   * current scenario. Returns null, or the message of a bad input (also shown in the banner).
   */
  start(overrides = {}) {
    let request;
    try {
      request = { ...this.request(), ...overrides };
    } catch (e) {
      showError(`Plan: ${errorText(e)}`);
      return errorText(e);
    }
    this.cancel('restarted');
    clearError();
    const { app } = this.ctx;
    this.undoJson = app.scenario_json();
    this.undoPreset = $('preset').value;
    this.applied = null;
    this.points = [];
    this.result = null;
    this.kept = false;
    this.error = null;
    this.run = {
      id: null, request, t0: performance.now(), evaluations: 0,
      budget: request.budget ?? this.defaultBudget, best: null, messages: 0, improvements: 0,
      wallMs: null, workerMs: null, stopped: null,
    };
    this.status = 'running';
    this.arm(false);
    if (!this.open) this.setOpen(true);
    this.run.id = this.worker.post({ scenario: this.undoJson, request: JSON.stringify(request) });
    this.sync();
    this.drawChart();
    this.ctx.changed({ draw: true });
    return null;
  }

  /** Stop: cancels the running plan; the layout stays at the last improvement applied. */
  stop() {
    return this.cancel('stopped');
  }

  /**
   * Cancels a running plan (terminates the worker) for `reason`; a glide in progress ends on its
   * layout. Returns true if a plan was running.
   */
  cancel(reason) {
    if (this.status !== 'running') return false;
    this.worker.cancel();
    this.finishGlide(); // may complete a plan whose result already arrived
    if (this.status === 'running') {
      this.status = 'idle';
      this.run.stopped = reason;
      this.run.wallMs = performance.now() - this.run.t0;
    }
    this.sync();
    this.drawChart();
    this.ctx.changed({ draw: true });
    return true;
  }

  /** Undo: restores the scenario saved at Optimize (cancelling a running plan first). */
  undo() {
    if (this.undoJson === null) return false;
    this.cancel('undo');
    try {
      this.ctx.app.set_scenario_json(this.undoJson);
    } catch (e) {
      showError(`Undo: ${errorText(e)}`);
      return false;
    }
    $('preset').value = this.undoPreset;
    this.undoJson = null;
    this.applied = null;
    this.ctx.changed({ all: true });
    this.sync();
    return true;
  }

  /** True if `m` (a worker message) belongs to the running plan. */
  current(m) {
    return this.run && m.gen === this.run.id && this.status === 'running';
  }

  /** A progress message of the plan: evaluations, history points, the newest improvement. */
  progress(m) {
    if (!this.current(m)) return;
    const r = this.run;
    r.messages += 1;
    r.evaluations = m.evaluations;
    r.budget = m.budget;
    for (const p of m.points) this.points.push(p);
    if (m.improvement) {
      r.improvements += 1;
      r.best = m.improvement.best;
      this.glideTo(m.improvement.scenario);
    }
    this.sync();
    this.drawChart();
  }

  /** The plan's result (plan.json): the nodes glide to its layout, then the plan is done. */
  finish(m) {
    if (!this.current(m)) return;
    const r = this.run;
    r.wallMs = performance.now() - r.t0;
    r.workerMs = m.ms;
    r.evaluations = m.result.evaluations;
    this.result = m.result;
    this.points = m.result.history.map((h) => [h.evaluations, h.best]);
    this.kept = sameLayout(JSON.parse(this.undoJson), m.result.scenario) || !improved(m.result.objective);
    if (this.kept) {
      // No better layout: the one from before Optimize stays, exactly (the glides undone).
      this.glide = null;
      if (this.frame) cancelAnimationFrame(this.frame);
      this.frame = 0;
      if (this.apply(this.undoJson, true)) $('preset').value = this.undoPreset;
      this.applied = null;
      this.undoJson = null;
      this.status = 'done';
      this.sync();
      this.drawChart();
      return;
    }
    this.glideTo(JSON.stringify(m.result.scenario), () => {
      this.status = 'done';
      this.sync();
    });
    this.sync();
    this.drawChart();
  }

  fail(message) {
    this.worker.cancel();
    this.finishGlide();
    this.status = 'error';
    this.error = message;
    if (this.run) this.run.wallMs = performance.now() - this.run.t0;
    if (this.applied === null) this.undoJson = null; // nothing to undo
    showError(`Plan: ${message}`);
    this.sync();
    this.ctx.changed({ draw: true });
  }

  // ---------- the nodes glide ----------

  /** Glides the nodes from where they are shown to the scenario `text` (JSON); then `onEnd()`. */
  glideTo(text, onEnd = null) {
    let to;
    try {
      to = JSON.parse(text);
    } catch (e) {
      this.fail(`the planner sent a layout that is not JSON (${errorText(e)})`);
      return;
    }
    if (this.glide && this.glide.onEnd) this.finishGlide();
    const from = this.glide ? this.glide.now : this.ctx.app.scenario();
    this.glide = { from, to, text, now: from, t0: performance.now(), onEnd };
    if (!this.frame) this.frame = requestAnimationFrame(() => this.step());
  }

  step() {
    this.frame = 0;
    const g = this.glide;
    if (!g) return;
    const f = (performance.now() - g.t0) / GLIDE_MS;
    if (f >= 1) {
      this.finishGlide();
      return;
    }
    g.now = between(g.from, g.to, smooth(f));
    this.apply(JSON.stringify(g.now), false);
    this.frame = requestAnimationFrame(() => this.step());
  }

  /** Ends a glide at once on its layout. */
  finishGlide() {
    const g = this.glide;
    if (!g) return;
    if (this.frame) cancelAnimationFrame(this.frame);
    this.frame = 0;
    this.glide = null;
    if (this.apply(g.text, true)) this.applied = g.text;
    if (g.onEnd) g.onEnd();
  }

  /** Applies scenario JSON to the App; `final`: the map at full resolution (else a drag's). */
  apply(text, final) {
    try {
      this.ctx.app.set_scenario_json(text);
    } catch (e) {
      showError(`Plan: the layout could not be applied: ${errorText(e)}`);
      return false;
    }
    $('preset').value = '';
    this.ctx.changed(final ? { all: true, dragEnd: true } : { all: true, dragging: true });
    return true;
  }

  // ---------- read-outs ----------

  /** An objective value as text: a length (mean, p90, max) or a percentage (coverage). */
  format(v, kind) {
    if (kind === 'coverage') return v === null ? '—' : `${fixed(v * 100, 1)} %`;
    return v === null ? '∞ (unbounded)' : this.ctx.wasm.format_length(v, 4);
  }

  kind() {
    const r = this.run && this.run.request;
    return r ? String(r.objective).split(':')[0] : $('plan-objective').value;
  }

  /** Buttons, the ROI text, the progress bar and the status line from the state. */
  sync() {
    const running = this.status === 'running';
    $('plan-t-label').hidden = $('plan-objective').value !== 'coverage';
    $('plan-run').disabled = running;
    $('plan-stop').disabled = !running;
    $('plan-undo').disabled = this.undoJson === null;
    const draw = $('plan-roi-draw');
    draw.setAttribute('aria-pressed', String(this.drawing));
    draw.textContent = this.drawing ? 'Drag on the map…' : 'Draw ROI';
    $('plan-roi-reset').disabled = this.roi === null;
    const [x0, x1, y0, y1] = this.roiArea();
    $('plan-roi-text').textContent =
      `x ${fixed(x0, 2)} … ${fixed(x1, 2)} m, y ${fixed(y0, 2)} … ${fixed(y1, 2)} m${this.roi ? '' : ' (whole area)'}`;
    const r = this.run;
    const bar = $('plan-bar');
    bar.style.width = r ? `${Math.min(100, (100 * r.evaluations) / Math.max(1, r.budget))}%` : '0';
    bar.classList.toggle('running', running);
    const el = $('plan-status');
    el.dataset.state = this.status;
    const res = $('plan-result');
    res.hidden = !(this.result && this.status === 'done');
    const kind = this.kind();
    const label = r ? r.request.objective : kind;
    if (!r) {
      el.textContent = 'Optimize moves the chosen nodes to improve the objective over the ROI (CMA-ES in a '
        + 'Web Worker). A node drag, Stop or a scenario change cancels it.';
    } else if (running) {
      el.textContent = `Optimizing ${label}: ${r.evaluations} / ${r.budget} evaluations · `
        + `${r.improvements} improvement${r.improvements === 1 ? '' : 's'}`
        + (r.improvements ? ` · best ${this.format(r.best, kind)} (search grid)` : '');
    } else if (this.status === 'done' && this.result) {
      const o = this.result.objective;
      const holes = o.unbounded_before || o.unbounded_after
        ? ` · unbounded cells ${o.unbounded_before} → ${o.unbounded_after}` : '';
      res.replaceChildren();
      const b = document.createElement('b');
      b.textContent = `${this.format(o.before, o.kind)} → ${this.format(o.after, o.kind)}`;
      if (this.kept) {
        b.textContent = `No better layout found: the current one is kept (${this.format(o.before, o.kind)}).`;
        res.append(b, ` ${o.label} on the ${o.grid}×${o.grid} ROI grid${holes}`);
      } else {
        res.append(`${o.label} on the ${o.grid}×${o.grid} ROI grid: `, b, holes);
      }
      el.textContent = `${this.result.evaluations} evaluations · ${this.result.runs} CMA-ES run`
        + `${this.result.runs === 1 ? '' : 's'} (${this.result.termination}) · `
        + (this.kept ? 'no better layout found: the current one is kept'
          : `moved ${this.result.moved.join(', ')}`)
        + ` · ${fixed(r.wallMs / 1000, 1)} s`;
    } else if (this.status === 'error') {
      el.textContent = `Failed: ${this.error}`;
    } else {
      el.textContent = `Stopped (${r.stopped}) after ${r.evaluations} evaluations: `
        + (this.applied ? 'the layout is the best found so far' : 'the layout is unchanged')
        + (this.undoJson !== null ? '; Undo restores the one from before.' : '.');
    }
  }

  /** The chart: the best objective (search grid) against evaluations, a step line. */
  drawChart() {
    const canvas = $('plan-chart');
    if (!canvas.getClientRects().length) return; // hidden
    const { width, height, dpr } = fitCanvas(canvas);
    const g = canvas.getContext('2d');
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = C.bg;
    g.fillRect(0, 0, canvas.width, canvas.height);
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const box = { x: 52, y: 10, w: Math.max(10, width - 80), h: Math.max(10, height - 34) };
    const r = this.run;
    const budget = Math.max(1, r ? r.budget : this.defaultBudget);
    const now = r ? r.evaluations : 0;
    const pts = this.points.filter(([, b]) => typeof b === 'number' && Number.isFinite(b));
    this.chartPoints = pts.length;
    g.font = FONT;
    g.strokeStyle = C.frame;
    g.lineWidth = 1;
    g.strokeRect(box.x + 0.5, box.y + 0.5, box.w, box.h);
    const w = this.ctx.wasm;
    g.fillStyle = C.muted;
    g.textAlign = 'center';
    g.textBaseline = 'top';
    const X = (e) => box.x + (Math.min(e, budget) / budget) * box.w;
    for (const t of w.axis_ticks(0, budget, 4)) g.fillText(t.label, X(t.value), box.y + box.h + 4);
    if (!pts.length) {
      g.textBaseline = 'middle';
      g.fillText(r ? 'waiting for the first feasible layout…' : 'objective (search grid) vs evaluations',
        box.x + box.w / 2, box.y + box.h / 2);
      return;
    }
    let lo = Math.min(...pts.map((p) => p[1]));
    let hi = Math.max(...pts.map((p) => p[1]));
    if (!(hi > lo)) {
      const pad = Math.abs(lo) * 0.05 || 0.01;
      lo -= pad;
      hi += pad;
    }
    const Y = (v) => box.y + box.h - ((v - lo) / (hi - lo)) * box.h;
    g.textAlign = 'right';
    g.textBaseline = 'middle';
    g.strokeStyle = C.grid;
    for (const t of w.axis_ticks(lo, hi, 4)) {
      const y = Math.round(Y(t.value)) + 0.5;
      g.beginPath(); g.moveTo(box.x, y); g.lineTo(box.x + box.w, y); g.stroke();
      g.fillText(t.label, box.x - 5, y);
    }
    g.strokeStyle = C.crlb;
    g.lineWidth = 1.75;
    g.beginPath();
    pts.forEach(([e, b], i) => {
      if (i === 0) g.moveTo(X(e), Y(b));
      else g.lineTo(X(e), Y(pts[i - 1][1]));
      g.lineTo(X(e), Y(b));
    });
    g.lineTo(X(Math.max(now, pts[pts.length - 1][0])), Y(pts[pts.length - 1][1]));
    g.stroke();
    g.fillStyle = C.crlb;
    for (const [e, b] of pts) {
      g.beginPath(); g.arc(X(e), Y(b), 2, 0, 2 * Math.PI); g.fill();
    }
  }

  /** What the tests read (hooks.js window.plan.state()). */
  state() {
    const r = this.run;
    return {
      state: this.status,
      evaluations: r ? r.evaluations : 0,
      budget: r ? r.budget : null,
      messages: r ? r.messages : 0,
      improvements: r ? r.improvements : 0,
      points: this.points.length,
      chartPoints: this.chartPoints,
      gliding: !!this.glide,
      wallMs: r ? r.wallMs : null,
      workerMs: r ? r.workerMs : null,
      stopped: r ? r.stopped : null,
      request: r ? r.request : null,
      applied: this.applied,
      undo: this.undoJson !== null,
      roi: this.roiArea(),
      roiCustom: this.roi !== null,
      open: this.open,
      drawing: this.drawing,
      error: this.error,
      kept: !!this.kept,
    };
  }
}

/**
 * Registers the page state's `plan` section: the Plan panel's choices and numbers (FIELDS'
 * ranges) and the region of interest (checked against the new scenario's area, `pending.area`).
 * @param {Plan} plan - the Plan panel
 * @param {object} ctx - app.js ctx (ctx.changed)
 */
export function registerPlanState(plan, ctx) {
  const PLAN = [['move', 'plan-move'], ['objective', 'plan-objective'], ['grid', 'plan-grid']];
  const PLAN_NUM = [['t', 'plan-t'], ['budget', 'plan-budget'], ['seed', 'plan-seed']];
  registerSection('plan', {
    get: () => {
      const o = { roi: plan.roi ? [...plan.roi] : null };
      for (const [k, id] of PLAN) o[k] = id === 'plan-grid' ? Number($(id).value) : $(id).value;
      for (const [k, id] of PLAN_NUM) o[k] = inputNumber(id, Number($(id).defaultValue));
      return o;
    },
    check: (v, pending) => {
      fields(v, 'state.plan', ['roi', ...PLAN.map((x) => x[0]), ...PLAN_NUM.map((x) => x[0])]);
      for (const [k, id] of PLAN) choice(v[k], `state.plan.${k}`, id);
      for (const [k, id] of PLAN_NUM) number(v[k], `state.plan.${k}`, FIELDS[id]);
      if (v.roi !== null) {
        rect(v.roi, 'state.plan.roi');
        try {
          plan.checkRoi(v.roi, pending.area);
        } catch (e) {
          throw new Error(`state.plan.roi: ${errorText(e)}`);
        }
      }
    },
    apply: (v) => {
      for (const [k, id] of [...PLAN, ...PLAN_NUM]) $(id).value = String(v[k]);
      for (const [, id] of PLAN_NUM) $(id).classList.remove('invalid');
      plan.roi = v.roi ? [...v.roi] : null;
      plan.sync();
      ctx.changed({ draw: true });
    },
  });
}
