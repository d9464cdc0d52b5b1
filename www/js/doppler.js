// The snapshot view's Doppler control (issue 42 §1): off (the delay-only map) or on, with the
// coherent processing interval (N snapshots T apart, the floor on the range rate's σ) and the
// target's velocity. On, the main map is the position bound with delays and range rates and a
// second map beside it the velocity bound (m/s, its own colour bar), both over the window and
// grid of the main map: map.js computes them through its one timing and resolution logic (the
// core's App.compute_doppler_maps_in, the map worker for a costly map), this file holds the
// fields, the page state's `doppler` section and the velocity map's drawing. Its job() settings
// also drive the map's hover read-out and pinned probe (interact.js, map.js: App.doppler_at, the
// bounds at a point) and Save figure (export.js: "Map" and "Velocity map" with Doppler, as
// `crlb-map --doppler --quantity position|velocity --out f.svg` draws them). Every number is
// read strictly (dom.js decimalIn); a bad one is named in the banner and the last good settings
// stay in use.

import { $, clearError, decimalIn, errorText, showError } from './dom.js';
import { View } from './view.js';
import { C, clipTo, drawAxes, drawScaleBar } from './draw.js';
import { drawColorbar, drawMap, drawNetwork } from './map.js';
import { registerSection } from './state.js';
import { fields, flag, inputNumber, number } from './state-fields.js';

/**
 * The inputs: the state's key, the name in messages and the allowed range (the core's: N in
 * 1 … MAX_CPI_SNAPSHOTS, T > 0, floor ≥ 0, a finite velocity; measure::Cpi::new).
 */
const FIELDS = {
  'doppler-n': { key: 'snapshots', name: 'Doppler N (cpi.snapshots)', min: 1, max: 1048576, integer: true },
  'doppler-t': { key: 'spacing_ms', name: 'Doppler T (cpi.spacing)', min: 0.000001, max: 1000000, unit: 'ms' },
  'doppler-floor': { key: 'floor_mps', name: 'Doppler σṙ floor (cpi.floor_mps)', min: 0, max: 1000000, unit: 'm/s' },
  'doppler-vx': { key: 'vx_mps', name: 'Doppler vx (velocity.x)', min: -1000000, max: 1000000, unit: 'm/s' },
  'doppler-vy': { key: 'vy_mps', name: 'Doppler vy (velocity.y)', min: -1000000, max: 1000000, unit: 'm/s' },
};
const IDS = Object.keys(FIELDS);

export class Doppler {
  /** @param {object} ctx - app.js ctx {app, wasm, st, view, changed} (after MapView). */
  constructor(ctx) {
    this.ctx = ctx;
    const { st } = ctx;
    this.view = new View($('vel-plot'));
    // The velocity map's drawing state, shaped as map.js's drawMap / drawColorbar read it.
    this.vel = {
      mapCanvas: document.createElement('canvas'),
      image: null,
      mapWindow: null,
      range: null,
      clamped: [0, 0],
      barCanvas: st.barCanvas,
      unboundedColor: st.unboundedColor,
    };
    this.valid = this.read(); // the defaults of the inputs
    this.error = null; // the banner's message of a bad field, while it is bad
    $('doppler-on').addEventListener('change', () => this.sync());
    for (const id of IDS) {
      const el = $(id);
      el.setAttribute('inputmode', 'decimal');
      el.setAttribute('autocomplete', 'off');
      el.setAttribute('spellcheck', 'false');
      el.addEventListener('change', () => this.edit());
    }
  }

  /** True when the control is on. */
  on() {
    return $('doppler-on').value === 'on';
  }

  /** True when the maps with Doppler are shown (on, in the snapshot view). */
  shown() {
    return this.on() && this.ctx.st.mode === 'snapshot';
  }

  /** The fields' values ({snapshots, spacing_ms, floor_mps, vx_mps, vy_mps}); throws the first bad one, named. */
  read() {
    const out = {};
    let first = null;
    for (const id of IDS) {
      const f = FIELDS[id];
      try {
        out[f.key] = decimalIn($(id).value, f.name, f);
        $(id).classList.remove('invalid');
      } catch (e) {
        $(id).classList.add('invalid');
        first = first || e;
      }
    }
    if (first) throw first;
    return out;
  }

  /** A field changed: good values are used (the map recomputed when on); a bad one is named. */
  edit() {
    try {
      this.valid = this.read();
      this.clearOwnError();
      if (this.shown()) this.ctx.changed({ map: true });
    } catch (e) {
      this.error = `Doppler: ${errorText(e)}`;
      showError(this.error);
    }
  }

  /** Hides the banner if it shows this control's error. */
  clearOwnError() {
    if (this.error && $('error-text').textContent === this.error) clearError();
    this.error = null;
  }

  /**
   * The settings of the next map (map.js): null for the delay-only map, else the core's
   * {cpi: {snapshots, spacing_ms, floor_mps}, velocity_mps: [vx, vy]} (the last good fields).
   */
  job() {
    if (!this.shown()) return null;
    const v = this.valid;
    return {
      cpi: { snapshots: v.snapshots, spacing_ms: v.spacing_ms, floor_mps: v.floor_mps },
      velocity_mps: [v.vx_mps, v.vy_mps],
    };
  }

  /**
   * Shows or hides the velocity map beside the main one (after the control or the view
   * changed) and asks for the map of the kernel now wanted.
   */
  sync() {
    const { st, view } = this.ctx;
    const pair = this.shown();
    $('plot').parentElement.classList.toggle('doppler-pair', pair);
    $('vel-plot').hidden = !pair;
    $('doppler-head').hidden = !pair;
    view.resize();
    if (pair) this.view.resize();
    // Save figure's "Velocity map" choice (export.js) exists only with the pair shown.
    if (this.ctx.figures) this.ctx.figures.relabel();
    const want = pair ? 'doppler' : 'delay';
    this.ctx.changed(st.mapKernel !== want ? { map: true } : { draw: true });
  }

  /** Colours the velocity map (its own scale over its finite values), when there is one. */
  paint() {
    const { st, wasm } = this.ctx;
    const v = this.vel;
    if (!st.velValues) return;
    const n = st.res;
    if (!v.image || v.image.width !== n) {
      v.image = new ImageData(n, n);
      v.mapCanvas.width = n;
      v.mapCanvas.height = n;
    }
    const r = wasm.render_map_rgba(st.velValues, v.image.data);
    v.range = r;
    v.mapWindow = st.mapWindow;
    v.mapCanvas.getContext('2d').putImageData(v.image, 0, 0);
  }

  /** Draws the velocity map over the main view's window (nothing unless shown). */
  draw() {
    const { st, wasm } = this.ctx;
    if (!this.shown()) return;
    const view = this.view;
    view.area = Array.from(this.ctx.view.area);
    view.resize();
    const ctx = view.context();
    view.clear(ctx, C.bg);
    if (st.velValues && st.mapKernel === 'doppler') drawMap(ctx, view, this.vel);
    drawAxes(ctx, view, wasm);
    drawColorbar(ctx, view, this.vel, wasm, '/s');
    // Zoomed in, the nodes stay inside the plot (as on the main map).
    const zoomed = this.ctx.view.zoomed();
    if (zoomed) clipTo(ctx, view.rect);
    drawNetwork(ctx, view, st.nodes, null);
    if (zoomed) ctx.restore();
    drawScaleBar(ctx, view, wasm);
  }

  /** The e2e hooks (hooks.js: window.doppler). */
  hooks() {
    const { st } = this.ctx;
    return {
      state: () => ({
        on: this.on(), shown: this.shown(), kernel: st.mapKernel, settings: { ...this.valid }, error: this.error,
        velocityRange: this.vel.range ? Array.from(this.vel.range) : null,
        colourBar: this.view.drawn.colourBar ? JSON.parse(JSON.stringify(this.view.drawn.colourBar)) : null,
      }),
      maps: () => ({
        kernel: st.mapKernel, res: st.res, window: st.mapWindow ? Array.from(st.mapWindow) : null,
        position: st.values ? Array.from(st.values) : null,
        velocity: st.velValues ? Array.from(st.velValues) : null,
      }),
      // The velocity image's colour of cell k (row 0 = lowest y), [r, g, b, a], or null.
      cellColour: (k) => (this.vel.image ? Array.from(this.vel.image.data.slice(4 * k, 4 * k + 4)) : null),
    };
  }
}

/**
 * Registers the page state's `doppler` section: {on, snapshots, spacing_ms, floor_mps, vx_mps,
 * vy_mps} (optional: a state saved before it leaves the control as it is).
 * @param {Doppler} doppler
 * @param {object} ctx - app.js ctx
 */
export function registerDopplerState(doppler, ctx) {
  const keys = ['on', ...IDS.map((id) => FIELDS[id].key)];
  registerSection('doppler', {
    optional: true,
    get: () => {
      const o = { on: doppler.on() };
      for (const id of IDS) o[FIELDS[id].key] = inputNumber(id, Number($(id).defaultValue));
      return o;
    },
    check: (v) => {
      fields(v, 'state.doppler', keys);
      flag(v.on, 'state.doppler.on');
      for (const id of IDS) number(v[FIELDS[id].key], `state.doppler.${FIELDS[id].key}`, FIELDS[id]);
    },
    apply: (v) => {
      $('doppler-on').value = v.on ? 'on' : 'off';
      for (const id of IDS) $(id).value = String(v[FIELDS[id].key]);
      doppler.valid = doppler.read();
      doppler.clearOwnError();
      doppler.sync();
      ctx.changed({ map: true });
    },
  });
}
