// The tracking view: simulates a track with the wasm core (App.simulate_track: the EKF, UKF or
// particle filter chosen), animates it over the CRLB map (play/pause, scrub, speed), lets the user
// draw a trajectory (press = start, drag = where it is after the run's duration) and keeps the
// Monte Carlo chart (montecarlo.js, the filters ticked) in step: every change of scenario, nodes or
// trajectory re-simulates the track and restarts the Monte Carlo. With "Several people" on
// (multi.js) the same transport animates the multi-target run instead, and its GOSPA chart
// takes the Monte Carlo's place; with its walkers "drawn", a press-drag on the map adds a walker's
// path and the run restarts when the drag ends.

import { $, decimalIn, errorText, fillKeyValues, fixed, showError, clearError } from './dom.js';
import { MonteCarlo } from './montecarlo.js';
import { MAX_PATHS, Multi } from './multi.js';
import { drawTrack } from './track-draw.js';
import { registerSection } from './state.js';
import { choice, fields, inputNumber, isObject, number, shown } from './state-fields.js';

/** The run's duration, s: the scenarios of spec §9.4 last 10 s (a drawn trajectory too). */
export const DURATION_S = 10;
// The particle filter's share of a browser Monte Carlo study: runs × steps × particles at most this
// (the job runs the leading chunks of 16 runs that fit, at least one); about 3 s in the worker.
export const PARTICLE_BUDGET = 20_000_000;
/** The filters of the panel (the Monte Carlo's check boxes mc-ekf, mc-ukf, mc-pf). */
export const FILTERS = ['ekf', 'ukf', 'pf'];
/** The range of the seed inputs (a u32 of the core; also the URL's `seed` and `tseed`). */
export const SEED_RANGE = { min: 0, max: 4294967295, integer: true };

export class Tracking {
  /** @param {object} ctx - {app, wasm, st, view, changed}; @param {object} opts - hash options. */
  constructor(ctx, opts) {
    this.ctx = ctx;
    this.kind = ['I', 'II', 'III', 'custom'].includes(opts.track) ? opts.track : 'I';
    this.drawn = opts.custom || { x0: -4, y0: 17, x1: 20, y1: 12 };
    this.step = 0;
    this.pos = 0; // fractional step while playing
    this.playing = false;
    this.track = null;
    this.data = null;
    this.frame = null;
    this.dragging = false;
    this.mc = new MonteCarlo(ctx.wasm, ctx.module, showError);
    this.multi = new Multi(ctx, { onResult: () => this.multiArrived(), onError: showError });
    // URL options arrive checked (app.js): each choice one of its <select>'s values.
    for (const [id, v] of [['track-kind', this.kind], ['track-dt', opts.dt], ['track-seed', opts.tseed],
      ['track-ex', opts.ex], ['mc-runs', opts.runs], ['track-speed', opts.speed], ['track-filter', opts.filter],
      ['track-particles', opts.particles]]) {
      if (v !== null && v !== undefined && v !== '') $(id).value = String(v);
    }
    if (opts.filters) for (const f of FILTERS) $(`mc-${f}`).checked = opts.filters.includes(f);
    const rerun = () => this.panelChanged();
    $('track-kind').addEventListener('change', () => { this.kind = $('track-kind').value; rerun(); });
    $('track-dt').addEventListener('change', rerun);
    $('track-seed').addEventListener('change', rerun);
    $('multi-walkers').addEventListener('change', () => { this.multi.walkersChosen(); this.multiChanged(); });
    $('multi-clear').addEventListener('click', () => { this.multi.clearPaths(); this.multiChanged(); });
    $('multi-method').addEventListener('change', rerun);
    $('track-filter').addEventListener('change', rerun);
    $('track-particles').addEventListener('change', rerun);
    for (const f of FILTERS) $(`mc-${f}`).addEventListener('change', () => this.startMc());
    $('mc-runs').addEventListener('change', () => this.startMc());
    $('mc-restart').addEventListener('click', () => this.startMc());
    $('track-ex').addEventListener('change', () => this.redraw());
    $('track-play').addEventListener('click', () => (this.playing ? this.pause() : this.play()));
    // The slider's new value is read before pause() redraws the transport (it resets the slider).
    $('track-scrub').addEventListener('input', () => {
      const n = Number($('track-scrub').value);
      this.pause();
      this.seek(n);
    });
    this.tickFn = (now) => this.tick(now);
    this.startStep = opts.step;
  }

  active() { return this.ctx.st.mode === 'tracking'; }

  /** The prior's parameters for the core: {kind, x0, y0, vx, vy, dt_s, steps, seed}. */
  params() {
    const w = this.ctx.wasm;
    const dt = Number($('track-dt').value);
    const steps = w.track_steps(DURATION_S, dt);
    let v = [0, 0];
    const d = this.drawn;
    if (this.kind === 'custom') v = w.drag_velocity(d.x0, d.y0, d.x1, d.y1, DURATION_S);
    const seed = decimalIn($('track-seed').value, 'seed', SEED_RANGE);
    const filter = $('track-filter').value;
    const particles = Number($('track-particles').value);
    return { kind: this.kind, x0: d.x0, y0: d.y0, vx: v[0], vy: v[1], dt_s: dt, steps, seed, filter, particles };
  }

  /** The animated track's filter, `EKF`, `UKF` or `PF` (the one chosen until a track exists). */
  filterName() {
    if (this.multi.on) return $('multi-method').value.toUpperCase();
    return (this.data ? this.data.filter : $('track-filter').value).toUpperCase();
  }

  /** Entries of the run animated: the multi-target run's scans, or the track's steps. */
  entries() {
    if (this.multi.on) return this.multi.entries();
    return this.track ? this.track.entries() : 0;
  }

  /** "Several people" switched on or off: the view changes, the run starts or the single view returns. */
  multiChanged() {
    document.body.classList.toggle('multi-on', this.multi.on);
    this.pause();
    if (!this.multi.on) {
      this.multi.cancel();
      this.frame = null;
    }
    this.panelChanged();
    if (!this.multi.on) this.mc.drawChart();
  }

  /** The multi-target run of the panel's walkers, method and seed (in the worker, multi.js). */
  rerunMulti() {
    this.mc.cancel();
    this.frame = null; // no single-target markers, iso-delays or inset
    try {
      const seed = decimalIn($('track-seed').value, 'seed', SEED_RANGE);
      $('track-seed').classList.remove('invalid');
      if (this.failed) clearError();
      this.failed = false;
      const m = this.multi;
      if (m.drawing && !m.paths.length) {
        m.waitForPaths();
      } else {
        m.start({
          scenario: this.ctx.app.scenario_json(), walkers: m.walkers(),
          ...(m.drawing ? { paths: m.pathRows() } : {}), method: $('multi-method').value, seed,
        });
      }
    } catch (e) {
      $('track-seed').classList.toggle('invalid', /seed/.test(errorText(e)));
      showError(errorText(e));
      this.failed = true;
    }
    this.step = 0;
    $('track-scrub').max = '0';
    $('track-filter-label').textContent = this.filterName();
    this.show();
  }

  /** A multi-target document arrived: the transport spans its scans; the map and read-out show it. */
  multiArrived() {
    if (!this.active() || !this.multi.on) return;
    $('track-scrub').max = String(this.entries() - 1);
    this.seek(Math.min(this.step, this.entries() - 1));
  }

  /** The filters ticked for the Monte Carlo, in the order EKF, UKF, PF (at least the EKF). */
  mcFilters() {
    const on = FILTERS.filter((f) => $(`mc-${f}`).checked);
    return on.length ? on : ['ekf'];
  }

  /**
   * A change in the panel (scenario, T, seed, filter, particles): re-simulates and redraws every
   * layer that shows the run (the map's truth and track, the inset and its title, the legend),
   * as Play or the slider would, and restarts the Monte Carlo.
   */
  panelChanged() {
    this.rerun();
    this.redraw();
  }

  /**
   * Re-simulates the track (keeping the step) and restarts the Monte Carlo; the caller redraws
   * (app.js's refresh draws next, panelChanged asks for a frame).
   */
  rerun() {
    if (!this.active()) return;
    if (this.multi.on) {
      this.rerunMulti();
      return;
    }
    try {
      const p = this.params();
      const track = this.ctx.app.simulate_track(JSON.stringify({
        trajectory: { kind: p.kind, x0_m: p.x0, y0_m: p.y0, vx_mps: p.vx, vy_mps: p.vy },
        dt_s: p.dt_s, steps: p.steps, seed: p.seed, filter: p.filter, particles: p.particles,
      }));
      if (this.track) this.track.free();
      this.track = track;
      this.p = p;
      this.data = track.data();
      $('track-seed').classList.remove('invalid');
      if (this.failed) clearError();
      this.failed = false;
      if (this.startStep !== undefined) { this.step = this.startStep; this.startStep = undefined; }
      $('track-scrub').max = String(track.entries() - 1);
      this.seek(Math.min(this.step, track.entries() - 1), false);
      this.startMc();
    } catch (e) {
      $('track-seed').classList.toggle('invalid', /seed/.test(errorText(e)));
      showError(errorText(e));
      this.failed = true;
    }
    $('track-hint').hidden = this.kind !== 'custom';
    $('track-particles-wrap').hidden = $('track-filter').value !== 'pf' && !$('mc-pf').checked;
    $('track-filter-label').textContent = this.filterName();
  }

  startMc() {
    if (!this.active() || !this.p || this.multi.on) return;
    const p = this.p;
    const runs = Number($('mc-runs').value);
    const filters = this.mcFilters();
    $('track-particles-wrap').hidden = p.filter !== 'pf' && !filters.includes('pf');
    this.mc.start({
      scenario: this.ctx.app.scenario_json(), ...p, trajectories: runs, noise_runs: 1,
      filters: filters.join(','), particle_budget: PARTICLE_BUDGET,
    }, this.kind === 'custom' ? 'drawn trajectory' : `scenario ${this.kind}`);
  }

  /** Shows step `n` (frame from the core, read-outs, redraw). */
  seek(n, redraw = true) {
    if (!this.entries()) return;
    this.step = Math.max(0, Math.min(n, this.entries() - 1));
    this.pos = this.step;
    this.frame = this.multi.on ? null : this.track.frame(this.step);
    this.show();
    if (redraw) this.redraw();
  }

  redraw() { this.ctx.changed({ frame: true }); }

  play() {
    if (!this.entries()) return;
    if (this.step >= this.entries() - 1) this.seek(0);
    this.playing = true;
    this.last = performance.now();
    requestAnimationFrame(this.tickFn);
    this.show();
  }

  pause() {
    this.playing = false;
    this.show();
  }

  tick(now) {
    if (!this.playing || !this.entries()) return;
    const speed = Number($('track-speed').value);
    const dt = this.multi.on ? this.multi.doc.dt_s : this.p.dt_s;
    this.pos += ((now - this.last) / 1000) * speed / dt;
    this.last = now;
    const end = this.entries() - 1;
    const n = Math.min(Math.floor(this.pos), end);
    if (n >= end) this.playing = false;
    if (n !== this.step) this.seek(n); else this.show();
    if (this.playing) requestAnimationFrame(this.tickFn);
  }

  /** Mode switch: start (track + Monte Carlo) or stop everything. */
  setActive(on) {
    if (on) {
      this.rerun();
    } else {
      this.pause();
      this.mc.cancel();
      this.multi.cancel();
    }
  }

  /**
   * Pointer hooks from interact.js: in "draw" mode a press on the map starts a trajectory (with
   * "Several people" on and its walkers "drawn": a walker's path).
   */
  wantsDraw() { return this.active() && (this.multi.on ? this.multi.drawing : this.kind === 'custom'); }

  /** What a press-drag on the map does in draw mode (the hover hint). */
  drawHint() { return this.multi.on ? 'press and drag to draw a walker\'s path' : 'press and drag to draw a trajectory'; }

  drawStart(m) {
    this.dragging = true;
    this.pause();
    if (this.multi.on) this.multi.pathStart(m);
    else this.drawn = { x0: m.x, y0: m.y, x1: m.x, y1: m.y };
    this.redraw();
  }

  drawMove(m) {
    if (this.dragging && this.multi.on) {
      // The arrow follows; the run (about 100 ms) waits for the drag's end.
      this.multi.pathMove(m);
      this.redraw();
      return;
    }
    if (!this.dragging || (m.x === this.drawn.x1 && m.y === this.drawn.y1)) return;
    this.drawn = { ...this.drawn, x1: m.x, y1: m.y };
    // The particle filter's track costs tens of ms: it follows the arrow once the drag ends.
    const live = $('track-filter').value !== 'pf';
    if (live && (this.drawn.x1 !== this.drawn.x0 || this.drawn.y1 !== this.drawn.y0)) this.rerun();
    this.redraw();
  }

  drawEnd(m) {
    if (this.dragging && this.multi.on) {
      this.dragging = false;
      if (this.multi.pathEnd(m)) this.panelChanged();
      else this.redraw();
      return;
    }
    this.drawMove(m);
    this.dragging = false;
    if ($('track-filter').value === 'pf' && (this.drawn.x1 !== this.drawn.x0 || this.drawn.y1 !== this.drawn.y0)) {
      this.rerun();
      this.redraw();
    }
  }

  /** The layer drawn under the markers (see draw.js drawScene). */
  overlay(ctx, view) {
    const magnify = Number($('track-ex').value);
    if (this.multi.on) {
      this.layer = this.multi.draw(ctx, view, this.step, magnify);
      return;
    }
    let drawn = null;
    if (this.kind === 'custom') {
      const v = this.p && this.p.kind === 'custom' ? this.p : null;
      drawn = { ...this.drawn, label: v ? `v̄ = (${fixed(v.vx, 2)}, ${fixed(v.vy, 2)}) m/s` : '' };
    }
    this.layer = drawTrack(ctx, view, { data: this.data, step: this.step, magnify, drawn });
  }

  /** Points the zoom inset should not hide, weighted: the truth path, a drawn arrow, the nodes. */
  avoidPoints() {
    const pts = this.multi.on ? this.multi.avoidPoints() : this.data ? [...this.data.truth] : [];
    if (this.kind === 'custom' && !this.multi.on) {
      const d = this.drawn;
      pts.push([d.x0, d.y0, 10], [d.x1, d.y1, 10]);
    }
    const n = this.ctx.st.nodes;
    for (const p of [...n.transmitters, ...n.receivers]) pts.push([p.x, p.y, 1e6]); // never covered (inset.js HARD)
    return pts;
  }

  /** Transport controls and the step read-out (labels from the core). */
  show() {
    const f = this.frame;
    const n = Math.max(0, this.entries() - 1);
    $('track-play').textContent = this.playing ? '❚❚ Pause' : '▶ Play';
    $('track-play').dataset.playing = this.playing ? '1' : '0';
    $('track-scrub').value = String(this.step);
    if (this.multi.on) {
      const m = this.multi;
      $('track-time').textContent = m.doc ? `t = ${fixed(m.timeAt(this.step), 2)} s / ${fixed(m.timeAt(n), 2)} s · scan ${this.step}/${n}` : 't = –';
      fillKeyValues($('track-info'), m.rows(this.step));
      return;
    }
    if (!f || !this.data) return;
    const tEnd = this.data.t_s[n];
    $('track-time').textContent = `t = ${fixed(f.t_s, 2)} s / ${fixed(tEnd, 2)} s · step ${f.step}/${n}`;
    $('track-ex-label').textContent = `×${$('track-ex').value}`;
    const m2 = (x, y) => `${fixed(x, 3)}, ${fixed(y, 3)} m`;
    const name = this.filterName();
    const rows = [
      ['Truth', m2(f.truth.x, f.truth.y), ''],
      [`${name} estimate`, m2(f.fix.x, f.fix.y), 'fix'],
      ['Error ‖r̂ − r‖', f.fix.error_label, 'fix'],
      [`${name} σ √(P_xx+P_yy)`, f.fix.sigma_label, 'fix'],
      ['Snapshot CRLB here', f.crlb.rmse_label, 'crlb'],
      ['NIS', f.step === 0 ? '–' : `${fixed(f.fix.nis, 2)} (χ²₄ mean 4)`, ''],
    ];
    if (this.data.failed_at !== null) rows.push(['Filter failed at step', String(this.data.failed_at), '']);
    fillKeyValues($('track-info'), rows);
  }

  /** Test and console hook. */
  state() {
    const f = this.frame;
    const mc = this.mc;
    return {
      mode: this.ctx.st.mode, kind: this.kind, step: this.step,
      filter: this.data ? this.data.filter : null, particles: this.data ? this.data.particles : null,
      mcFilters: mc.params ? mc.params.filters : null,
      steps: this.track ? this.track.entries() - 1 : 0, playing: this.playing,
      t_s: f ? f.t_s : null, truth: f ? [f.truth.x, f.truth.y] : null, estimate: f ? [f.fix.x, f.fix.y] : null,
      mcState: mc.state, mcGeneration: mc.gen, mcRuns: mc.params ? mc.params.trajectories * mc.params.noise_runs : 0,
      mcMs: mc.ms, mcComputeMs: mc.computeMs, mcDone: mc.done, mcTotal: mc.total,
      mcElapsedMs: mc.elapsedMs, mcEtaMs: mc.etaMs,
      mcSuperseded: mc.superseded, chartSeries: mc.series, drawn: { ...this.drawn },
      layer: this.layer || null, multi: this.multi.snapshot(),
    };
  }
}

/**
 * Registers the page state's `tracking` section: the trajectory (kind, the drawn one), the
 * panel's choices, the seed and the Monte Carlo's filters. The playback speed is transient
 * (like the step, the view section's): saved and linked, not an edit.
 * @param {Tracking} tracking - the tracking view
 * @param {object} wasm - the core (check_point, track_field_ranges)
 */
export function registerTrackingState(tracking, wasm) {
  const TRACK = [['dt', 'track-dt'], ['ex', 'track-ex'], ['filter', 'track-filter'], ['particles', 'track-particles'],
    ['runs', 'mc-runs'], ['speed', 'track-speed']];
  registerSection('tracking', {
    transient: ['speed'],
    get: () => {
      const o = { kind: tracking.kind, drawn: { ...tracking.drawn } };
      for (const [k, id] of TRACK) o[k] = k === 'filter' ? $(id).value : Number($(id).value);
      o.seed = inputNumber('track-seed', tracking.p ? tracking.p.seed : 1);
      o.mc_filters = FILTERS.filter((f) => $(`mc-${f}`).checked);
      return o;
    },
    check: (v) => {
      fields(v, 'state.tracking', ['kind', 'drawn', ...TRACK.map((x) => x[0]), 'seed', 'mc_filters']);
      choice(v.kind, 'state.tracking.kind', 'track-kind');
      fields(v.drawn, 'state.tracking.drawn', ['x0', 'y0', 'x1', 'y1']);
      for (const c of ['x0', 'y0', 'x1', 'y1']) number(v.drawn[c], `state.tracking.drawn.${c}`);
      wasm.check_point('state.tracking.drawn.start', v.drawn.x0, v.drawn.y0);
      wasm.check_point('state.tracking.drawn.end', v.drawn.x1, v.drawn.y1);
      for (const [k, id] of TRACK) choice(v[k], `state.tracking.${k}`, id);
      number(v.seed, 'state.tracking.seed', SEED_RANGE);
      const f = v.mc_filters;
      if (!Array.isArray(f) || f.some((x) => !FILTERS.includes(x)) || new Set(f).size !== f.length) {
        throw new Error(`state.tracking.mc_filters: ${shown(f)} is not a list of distinct filters of ${FILTERS.join(', ')}`);
      }
    },
    apply: (v) => {
      for (const [k, id] of TRACK) $(id).value = String(v[k]);
      $('track-kind').value = v.kind;
      $('track-seed').value = String(v.seed);
      for (const f of FILTERS) $(`mc-${f}`).checked = v.mc_filters.includes(f);
      tracking.kind = v.kind;
      tracking.drawn = { ...v.drawn };
      tracking.rerun(); // (only in the tracking view)
      tracking.redraw();
    },
  });
  // Several people (issue 41): the walkers ('off', 1–5 or 'drawn'), the method and the drawn
  // paths ([[x0, y0, x1, y1], …] m, at most MAX_PATHS, each end a point the core takes); optional,
  // so a state saved before it opens as before (walkers off), and a state saved before the drawn
  // paths opens with none.
  const multi = tracking.multi;
  registerSection('multi', {
    optional: true,
    get: () => ({ walkers: $('multi-walkers').value, method: $('multi-method').value, paths: multi.pathRows() }),
    check: (v) => {
      fields(v, 'state.multi', isObject(v) && 'paths' in v ? ['walkers', 'method', 'paths'] : ['walkers', 'method']);
      choice(v.walkers, 'state.multi.walkers', 'multi-walkers');
      choice(v.method, 'state.multi.method', 'multi-method');
      const p = v.paths ?? [];
      if (!Array.isArray(p) || p.length > MAX_PATHS) {
        throw new Error(`state.multi.paths: ${shown(p)} is not a list of at most ${MAX_PATHS} paths [x0, y0, x1, y1]`);
      }
      p.forEach((q, i) => {
        const path = `state.multi.paths[${i}]`;
        if (!Array.isArray(q) || q.length !== 4) throw new Error(`${path}: ${shown(q)} is not [x0, y0, x1, y1]`);
        q.forEach((x, j) => number(x, `${path}[${j}]`));
        wasm.check_point(`${path}.start`, q[0], q[1]);
        wasm.check_point(`${path}.end`, q[2], q[3]);
      });
    },
    apply: (v) => {
      multi.paths = (v.paths ?? []).map(([x0, y0, x1, y1]) => ({ x0, y0, x1, y1 }));
      $('multi-walkers').value = v.walkers;
      $('multi-method').value = v.method;
      multi.walkersChosen();
      tracking.multiChanged();
    },
  });
}
