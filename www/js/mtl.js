// The multi-target view: state and events only. The scene (nodes, targets, scatterer discs, noise,
// clutter, thresholds, blocking model) lives here as the core's JSON schema; every edit is
// validated on the main thread, first its numbers by the page (strict decimals in the ranges of
// FIELDS), then the scene by the core (mtl_check_scene): a rejected edit shows the named message
// and changes nothing. The view is computed by the core in a Web Worker (mtl-worker.js; the
// newest scene wins, and a worker still busy with a stale scene STALE_MS after starting it is
// replaced, workers.js), then drawn by mtl-draw.js; while it computes, #mtl-status says so.

import { $, decimalIn, errorText, fillKeyValues, fixed, showError, clearError } from './dom.js';
import { JobWorker } from './workers.js';
import { MARGIN, View } from './view.js';
import { hitRadius, pickNearest } from './interact.js';
import { drawMtl } from './mtl-draw.js';
import { registerSection } from './state.js';
import { fields, inputNumber, isObject, number, rect, shown } from './state-fields.js';

/** Shown around the region, m. */
export const MARGIN_M = 0.4;
/** Where "+ target" / "+ disc" try to put a new one (first valid wins), m. */
const SPOTS = [[5, 5], [5, 7], [3, 6], [7, 3], [6, 8.5], [8, 6], [3, 2], [1.5, 7], [8.5, 1], [4.5, 2.5]];
/**
 * The scene's numeric inputs: [input id, scene key, on-screen name, allowed range]. The page's
 * documented ranges (README, "The page"; cσ and clutter from the core, mtl_field_ranges); the core
 * checks the scene again.
 */
const FIELDS = [
  ['mtl-seed', 'seed', 'seed', { min: 0, max: Number.MAX_SAFE_INTEGER, integer: true }],
  ['mtl-clutter', 'clutter_mean', 'clutter', { min: 0, max: 10, unit: 'peaks per TRP' }],
  ['mtl-sigma', 'range_sigma', 'cσ', { min: 1e-3, max: 1e3, unit: 'm' }],
  ['mtl-resolution', 'resolution', 'δ', { min: 0, max: 1e3, unit: 'm' }],
  ['mtl-pd', 'p_d', 'p_d', { min: 0, max: 1 }],
  ['mtl-lambda', 'lambda', 'λ', { min: 0, max: 10, unit: 'm⁻²' }],
  ['mtl-diameter', 'diameter', 'D', { min: 1e-3, max: 1e3, unit: 'm' }],
  ['mtl-te', 't_e', 'T_e', { min: 0, max: 6 }],
  ['mtl-tb', 't_b', 'T_b', { min: 0, max: 30, unit: 'nats' }],
  ['mtl-pu', 'model.p_u', 'p_u', { min: 0, max: 1 }],
  ['mtl-plos', 'model.p_los', 'p_LoS', { min: 0, max: 1 }],
];
/** The numeric inputs by id: {key, name, range}. */
export const FIELD = Object.fromEntries(FIELDS.map(([id, key, name, range]) => [id, { key, name, range }]));
/** A worker busy this long with a scene an edit has replaced is terminated and replaced, ms. */
const STALE_MS = 250;

/** Input `id`'s number, strictly parsed and range-checked; throws naming the field (`key (name): …`). */
function fieldValue(id) {
  const { key, name, range } = FIELD[id];
  return decimalIn($(id).value, key === name ? key : `${key} (${name})`, range);
}

/** The multi-target view's home: the scene's region [x0, x1, y0, y1] and a margin of MARGIN_M. */
export const mtlHome = ([x0, x1, y0, y1]) => [x0 - MARGIN_M, x1 + MARGIN_M, y0 - MARGIN_M, y1 + MARGIN_M];

export class Mtl {
  /** @param {object} ctx - {wasm, st, changed}. */
  constructor(ctx) {
    this.ctx = ctx;
    this.wasm = ctx.wasm;
    // The ranges the core also checks come from the core (one definition).
    for (const [key, [min, max]] of Object.entries(JSON.parse(this.wasm.mtl_field_ranges()))) {
      Object.assign(FIELDS.find((f) => f[1] === key)[3], { min, max });
    }
    this.canvas = $('plot');
    // No colour bar here: a narrow right margin.
    this.view = new View(this.canvas, { ...MARGIN, right: 24 });
    this.scene = JSON.parse(this.wasm.mtl_default_scene());
    this.result = null; // the last view from the core
    this.resultGen = 0;
    this.gen = 0; // generation of the scene last posted (the worker's job generation)
    this.ms = null; // the worker's time for the last view, ms
    this.computeMs = null; // the core's own time inside it
    this.msLog = []; // [worker ms, core ms] of the last views (at most 64), oldest first
    this.viewCount = 0; // views received so far
    this.workerError = null;
    this.selected = null; // {kind: 'tx' | 'rx' | 'target' | 'disc', index}
    this.press = null;
    this.job = new JobWorker(new URL('./mtl-worker.js', import.meta.url), ctx.module, {
      staleMs: STALE_MS,
      onResult: (m) => this.receive(m),
      onError: (message, gen) => this.fail(message, gen),
    });
    this.statusTimer = null;
    this.bindPanel();
    this.bindPointer();
    this.syncPanel();
  }

  active() { return this.ctx.st.mode === 'mtl'; }

  /** Mode switch: fit the region and recompute, or nothing (the worker idles). */
  setActive(on) {
    if (on) this.submit();
  }

  // ---------- scene edits ----------

  /**
   * Applies `edit` (a function changing a copy of the scene) if the core accepts the result:
   * then posts it to the worker; else shows the core's message and keeps the scene. Returns
   * whether it was accepted. `input` (an element) is marked invalid on rejection.
   */
  apply(edit, input) {
    const next = structuredClone(this.scene);
    try {
      edit(next);
      this.wasm.mtl_check_scene(JSON.stringify(next));
    } catch (e) {
      showError(errorText(e));
      if (input) input.classList.add('invalid');
      this.syncPanel();
      return false;
    }
    for (const el of $('mtl-section').querySelectorAll('input.invalid')) el.classList.remove('invalid');
    this.scene = next;
    clearError();
    this.submit();
    return true;
  }

  /** Posts the current scene to the worker and redraws (markers move at once). */
  submit() {
    this.gen = this.job.post({ scene: JSON.stringify(this.scene) });
    this.showTiming();
    this.ctx.changed({ mtl: true });
  }

  /**
   * A scene the core could not compute (e.g. over its candidate budget) or a worker failure: the
   * banner shows the message, the last view stays drawn.
   */
  fail(message, gen) {
    if (gen !== undefined) this.resultGen = Math.max(this.resultGen, gen);
    if (gen !== undefined && gen < this.gen) return; // a replaced scene's: not worth a banner
    this.workerError = message;
    showError(`Multi-target view: ${message}`);
    this.showTiming();
  }

  receive(m) {
    if (m.gen < this.resultGen) return;
    this.result = m.view;
    this.resultGen = m.gen;
    this.ms = m.ms;
    this.computeMs = m.view.compute_ms;
    this.msLog.push([m.ms, m.view.compute_ms]);
    if (this.msLog.length > 64) this.msLog.shift();
    this.viewCount += 1;
    this.workerError = null;
    this.showTiming();
    this.showInfo();
    if (this.active()) this.ctx.changed({ mtl: true });
  }

  /** The footer's timing and, while the worker computes for longer than STALE_MS, #mtl-status. */
  showTiming() {
    const el = $('mtl-ms');
    const pending = this.gen > this.resultGen;
    if (this.ms !== null) {
      el.dataset.ms = String(this.ms);
      el.dataset.computeMs = String(this.computeMs);
      el.textContent = `MTL recompute: ${fixed(this.ms, 1)} ms (worker)${pending ? ' …' : ''}`;
    }
    const busy = pending ? this.job.busyMs() : 0;
    const status = $('mtl-status');
    status.hidden = busy < STALE_MS;
    status.textContent = status.hidden ? '' : `Computing the view… ${fixed(busy / 1000, 1)} s (any edit replaces it)`;
    clearTimeout(this.statusTimer);
    if (pending) this.statusTimer = setTimeout(() => this.showTiming(), 100);
  }

  // ---------- panel ----------

  bindPanel() {
    for (const id of ['mtl-seed', 'mtl-clutter', 'mtl-sigma', 'mtl-pd', 'mtl-lambda', 'mtl-diameter', 'mtl-resolution']) {
      $(id).setAttribute('inputmode', 'decimal');
      $(id).setAttribute('autocomplete', 'off');
      $(id).addEventListener('change', () => this.apply((s) => { s[FIELD[id].key] = fieldValue(id); }, $(id)));
    }
    for (const id of ['mtl-te', 'mtl-tb']) {
      $(id).addEventListener('input', () => this.apply((s) => { s[FIELD[id].key] = fieldValue(id); }));
    }
    const model = () => this.apply((s) => { s.model = this.modelFromPanel(); },
      $('mtl-model').value === 'icb-plos' ? $('mtl-plos') : $('mtl-pu'));
    $('mtl-model').addEventListener('change', model);
    $('mtl-pu').addEventListener('change', model);
    $('mtl-plos').addEventListener('change', model);
    $('mtl-reseed').addEventListener('click', () => this.apply((s) => { s.seed += 1; }));
    $('mtl-reset').addEventListener('click', () => {
      this.scene = JSON.parse(this.wasm.mtl_default_scene());
      this.selected = null;
      clearError();
      this.submit();
    });
    $('mtl-add-target').addEventListener('click', () => this.add('targets'));
    $('mtl-add-disc').addEventListener('click', () => this.add('discs'));
    $('mtl-remove-target').addEventListener('click', () => this.remove('targets', 'target'));
    $('mtl-remove-disc').addEventListener('click', () => this.remove('discs', 'disc'));
  }

  /** The blocking model of the panel's selector. */
  modelFromPanel() {
    switch ($('mtl-model').value) {
      case 'ppp-exact': return { kind: 'ppp', exact: true };
      case 'icb-pu': return { kind: 'icb', p_u: fieldValue('mtl-pu') };
      case 'icb-plos': return { kind: 'icb', p_los: fieldValue('mtl-plos') };
      default: return { kind: 'ppp', exact: false };
    }
  }

  /** Adds a target or disc at the first spot the core accepts. */
  add(list) {
    for (const p of SPOTS) {
      const next = structuredClone(this.scene);
      next[list].push(p);
      try {
        this.wasm.mtl_check_scene(JSON.stringify(next));
      } catch (_) {
        continue;
      }
      this.apply((s) => { s[list].push(p); });
      this.selected = { kind: list === 'targets' ? 'target' : 'disc', index: this.scene[list].length - 1 };
      return;
    }
    // None fits: let the core say why for the first spot.
    this.apply((s) => { s[list].push(SPOTS[0]); });
  }

  /**
   * Removes the selected object of `kind` (a target or disc, or on Delete a node), or the last
   * one; the core judges the scene left. Returns whether it was removed.
   */
  remove(list, kind) {
    if (this.scene[list].length === 0) return false;
    const sel = this.selected && this.selected.kind === kind ? this.selected.index : this.scene[list].length - 1;
    const ok = this.apply((s) => { s[list].splice(sel, 1); });
    if (ok) this.selected = null;
    return ok;
  }

  /**
   * Moves object {kind, index} to (x, y) m if the core accepts the scene: the one path of a drag
   * and a keyboard move (keyboard.js). Returns whether the scene changed.
   */
  moveTo({ kind, index }, x, y) {
    const list = this.listOf(kind);
    const cur = this.scene[list][index];
    if (cur[0] === x && cur[1] === y) return false;
    return this.apply((s) => { s[list][index] = [x, y]; });
  }

  /** Panel inputs from the scene. */
  syncPanel() {
    const s = this.scene;
    for (const [id, v] of [['mtl-seed', s.seed], ['mtl-clutter', s.clutter_mean], ['mtl-sigma', s.range_sigma],
      ['mtl-pd', s.p_d], ['mtl-lambda', s.lambda], ['mtl-diameter', s.diameter], ['mtl-resolution', s.resolution]]) {
      if (document.activeElement !== $(id)) $(id).value = String(v);
    }
    $('mtl-te').value = String(s.t_e);
    $('mtl-tb').value = String(s.t_b);
    $('mtl-te-out').textContent = fixed(s.t_e, 1);
    $('mtl-tb-out').textContent = `${fixed(s.t_b, 2)} nats`;
    const m = s.model;
    $('mtl-model').value = m.kind === 'ppp' ? (m.exact ? 'ppp-exact' : 'ppp') : (m.p_los !== undefined ? 'icb-plos' : 'icb-pu');
    if (m.p_u !== undefined) $('mtl-pu').value = String(m.p_u);
    if (m.p_los !== undefined) $('mtl-plos').value = String(m.p_los);
    $('mtl-pu').disabled = $('mtl-model').value !== 'icb-pu';
    $('mtl-plos').disabled = $('mtl-model').value !== 'icb-plos';
    $('mtl-remove-target').disabled = s.targets.length === 0;
    $('mtl-remove-disc').disabled = s.discs.length === 0;
  }

  /** Read-outs of the last view (numbers from the core). */
  showInfo() {
    const v = this.result;
    if (!v) return;
    const m = v.metrics;
    const det = v.detected.map((d, i) => [`Detected #${i + 1}`,
      `(${fixed(d.x[0], 2)}, ${fixed(d.x[1], 2)}) m · |ℳ| ${d.matching.length} · J ${fixed(d.j, 2)} · L_b ${fixed(d.l_b, 2)}`,
      d.hit ? 'fix' : 'fa']);
    const tgt = v.targets.map((t, k) => [`Target T${k + 1}`,
      `(${fixed(t.x[0], 2)}, ${fixed(t.x[1], 2)}) m · ${t.dp_trps.length} DPs of ${t.los_trps.length} LoS TRPs · ${t.detected ? 'found' : 'missed'}`, '']);
    fillKeyValues($('mtl-info'), [
      ['Model', v.model.label, ''],
      ['TRPs · ranges', `${v.trps.length} · ${v.mpcs} (seeds ${v.seeds.length}, live ${v.hypotheses.length})`, ''],
      ['Detected K̂ / true K', `${m.estimates} / ${m.targets}`, ''],
      ['N_D · N_FA', `${m.detected} · ${m.false_alarms}`, ''],
      ['P_D · P_FA (this scene)', `${fixed(m.p_d, 2)} · ${fixed(m.p_fa, 2)}`, ''],
      ...tgt,
      ...det,
    ]);
    const rows = v.trps.map((t) => `TRP ${t.trp + 1} (Tx${t.tx + 1}–Rx${t.rx + 1}): `
      + t.ranges.map((r) => `${fixed(r.range_m, 2)}${r.source === 'dp' ? `ᵀ${r.target + 1}` : ''}`).join(', '));
    $('mtl-trps').textContent = rows.join('\n');
    if (!this.active()) return;
    $('readout').textContent = `Multi-target · ${v.trps.length} TRPs, ${v.mpcs} ranges · detected ${m.estimates} `
      + `(N_D ${m.detected}/${m.targets}, N_FA ${m.false_alarms}) · drag Tx, Rx, targets (×) and discs`;
  }

  // ---------- pointer (capture phase on the plot's parent, so interact.js never sees MTL events) ----------

  /**
   * The scene object under a canvas pixel: {kind, index} or null (nodes first, then targets,
   * discs); `radius` the pick radius (finger-sized for a touch press, see hitRadius).
   */
  hit(p, radius) {
    const s = this.scene;
    return pickNearest(this.view, [['disc', s.discs, this.view.len(s.diameter / 2)], ['target', s.targets],
      ['rx', s.receivers], ['tx', s.transmitters]], p, radius);
  }

  listOf(kind) {
    return { tx: 'transmitters', rx: 'receivers', target: 'targets', disc: 'discs' }[kind];
  }

  bindPointer() {
    const wrap = this.canvas.parentElement;
    const mine = (ev) => this.active() && ev.target === this.canvas;
    wrap.addEventListener('pointerdown', (ev) => {
      if (!mine(ev)) return;
      ev.stopPropagation();
      ev.preventDefault();
      if (ev.button !== 0) return;
      const p = this.view.eventPixel(ev);
      const h = this.hit(p, hitRadius(ev));
      this.selected = h;
      // On an object: drag it; on empty plot: pan the view (zoom.js).
      this.press = h ? { ...h } : this.view.inPlot(p.x, p.y) ? { pan: p } : null;
      if (this.press) {
        this.canvas.setPointerCapture(ev.pointerId);
        if (h) this.canvas.classList.add('dragging');
      }
      this.ctx.changed({ mtl: true });
    }, true);
    wrap.addEventListener('pointermove', (ev) => {
      if (!mine(ev)) return;
      ev.stopPropagation();
      const p = this.view.eventPixel(ev);
      if (!this.press) {
        this.canvas.classList.toggle('over-node', !!this.hit(p));
        return;
      }
      if (this.press.pan) {
        this.ctx.zoom.panBy(p.x - this.press.pan.x, p.y - this.press.pan.y);
        this.press.pan = p;
        this.press.panned = true;
        return;
      }
      // Keep the dragged object inside the region (clamped in pixels).
      const [x0, x1, y0, y1] = this.scene.region;
      const m = this.view.toMetreWithin(p, this.view.toPixel(x0, y1), this.view.toPixel(x1, y0));
      this.moveTo(this.press, m.x, m.y);
    }, true);
    const end = (ev) => {
      if (!mine(ev)) return;
      ev.stopPropagation();
      if (this.press && this.press.panned && ev.type === 'pointerup') {
        // The release point is where the map ends up (a move event may have been resampled).
        const p = this.view.eventPixel(ev);
        this.ctx.zoom.panBy(p.x - this.press.pan.x, p.y - this.press.pan.y);
      }
      this.cancelPress();
    };
    wrap.addEventListener('pointerup', end, true);
    wrap.addEventListener('pointercancel', end, true);
    wrap.addEventListener('pointerleave', (ev) => { if (mine(ev)) ev.stopPropagation(); }, true);
  }

  /** Ends a press (a release, or a second finger starting a pinch, zoom.js). */
  cancelPress() {
    if (this.press && this.press.panned) this.ctx.zoom.settle();
    this.press = null;
    this.canvas.classList.remove('dragging');
  }

  // ---------- drawing ----------

  /** Redraws the canvas (called by app.js's refresh in this mode). */
  draw() {
    this.view.resize();
    // The region and a margin; a zoomed window (zoom.js) stays until the region changes.
    this.view.setHome(mtlHome(this.scene.region));
    this.syncPanel();
    drawMtl(this.view, this.scene, this.result, this.selected, this.wasm);
  }

  /** Test and console hook: the scene, the last view's essentials, the colours drawn with (mtlColors) and the timing. */
  state() {
    const v = this.result;
    return {
      mode: this.ctx.st.mode,
      scene: structuredClone(this.scene),
      selected: this.selected,
      gen: this.gen,
      viewGen: this.resultGen,
      pending: this.gen !== this.resultGen,
      detected: v ? v.detected.map((d) => d.x) : [],
      targets: v ? v.targets.map((t) => t.x) : [],
      metrics: v ? v.metrics : null,
      blocked: v ? v.segments.filter((s) => s.blocked).length : 0,
      ms: this.ms,
      computeMs: this.computeMs,
      msLog: this.msLog.slice(),
      viewCount: this.viewCount,
      error: this.workerError,
      busyMs: this.job.busyMs(),
      restarts: this.job.restarts,
      labels: (this.view.drawn.labels || []).map((l) => ({ ...l, box: { ...l.box } })),
      colors: this.view.drawn.colors ? { ...this.view.drawn.colors } : null,
    };
  }

  /** Test hook: replaces the scene (JSON text or object); returns the core's message or null. */
  setScene(scene) {
    const text = typeof scene === 'string' ? scene : JSON.stringify(scene);
    let parsed;
    try {
      parsed = JSON.parse(this.wasm.mtl_check_scene(text));
    } catch (e) {
      showError(errorText(e));
      return errorText(e);
    }
    clearError();
    this.scene = parsed;
    this.submit();
    return null;
  }

  /** Test and console hook: `n` cold recomputes of the current scene on this thread, ms each. */
  bench(n = 9) {
    const text = JSON.stringify(this.scene);
    const out = [];
    for (let i = 0; i < n; i++) {
      const t0 = performance.now();
      this.wasm.mtl_view_of(text);
      out.push(performance.now() - t0);
    }
    return out;
  }

  /** Test hook: a scene point as CSS pixels relative to the canvas centre. */
  pixelFromCentre(x, y) {
    const p = this.view.toPixel(x, y);
    const r = this.canvas.getBoundingClientRect();
    return [p.x - r.width / 2, p.y - r.height / 2];
  }
}

/**
 * Registers the page state's `mtl` section: the scene (the core's check) and the two detection
 * probabilities. Its check hands the scene's region to the view section (`pending.region`).
 * @param {Mtl} mtl - the multi-target view
 * @param {object} wasm - the core (mtl_check_scene)
 */
export function registerMtlState(mtl, wasm) {
  registerSection('mtl', {
    get: () => ({
      scene: structuredClone(mtl.scene),
      p_u: inputNumber('mtl-pu', Number($('mtl-pu').defaultValue)),
      p_los: inputNumber('mtl-plos', Number($('mtl-plos').defaultValue)),
    }),
    check: (v, pending) => {
      fields(v, 'state.mtl', ['scene', 'p_u', 'p_los']);
      if (!isObject(v.scene)) throw new Error(`state.mtl.scene: ${shown(v.scene)} is not a scene object`);
      try {
        wasm.mtl_check_scene(JSON.stringify(v.scene));
      } catch (e) {
        throw new Error(`state.mtl.scene: ${errorText(e)}`);
      }
      number(v.p_u, 'state.mtl.p_u', FIELD['mtl-pu'].range);
      number(v.p_los, 'state.mtl.p_los', FIELD['mtl-plos'].range);
      pending.region = rect(v.scene.region, 'state.mtl.scene.region');
    },
    apply: (v) => {
      $('mtl-pu').value = String(v.p_u);
      $('mtl-plos').value = String(v.p_los);
      mtl.scene = structuredClone(v.scene);
      const n = mtl.selected && mtl.scene[mtl.listOf(mtl.selected.kind)];
      if (!n || mtl.selected.index >= n.length) mtl.selected = null;
      mtl.syncPanel();
      mtl.submit();
    },
  });
}
