// Page entry: loads the wasm core, owns the state and the refresh loop (one redraw per animation
// frame at most). All numbers come from the core; this file only routes events and draws.

import init, * as wasm from './pkg/scatterloc.js';
import { View } from './view.js';
import { drawScene, makeBarCanvas } from './draw.js';
import { Panel, showError } from './panel.js';
import { attachPointer } from './interact.js';
import { Tracking } from './track.js';
import { Mtl } from './mtl.js';

const $ = (id) => document.getElementById(id);

/**
 * `#preset=iclgnss2019&target=6,4&seed=3&res=256` -> options; tracking: `#mode=tracking&track=II&step=45
 * &play=1&runs=200&ex=100&tseed=1&dt=0.1&speed=1&custom=x0,y0,x1,y1`; multi-target: `#mode=mtl`.
 */
function hashOptions() {
  const h = new URLSearchParams(location.hash.slice(1));
  const target = (h.get('target') || '').split(',').map(Number);
  const custom = (h.get('custom') || '').split(',').map(Number);
  const int = (k) => (Number.isInteger(Number(h.get(k))) && h.get(k) ? Number(h.get(k)) : undefined);
  return {
    mode: ['tracking', 'mtl'].includes(h.get('mode')) ? h.get('mode') : 'snapshot',
    track: h.get('track'),
    step: int('step'),
    play: h.get('play') === '1',
    runs: h.get('runs'),
    ex: h.get('ex'),
    tseed: h.get('tseed'),
    dt: h.get('dt'),
    speed: h.get('speed'),
    custom: custom.length === 4 && custom.every(Number.isFinite)
      ? { x0: custom[0], y0: custom[1], x1: custom[2], y1: custom[3] } : null,
    preset: h.get('preset'),
    target: target.length === 2 && target.every(Number.isFinite) ? { x: target[0], y: target[1] } : null,
    seed: Number.isInteger(Number(h.get('seed'))) && h.get('seed') ? Number(h.get('seed')) : 1,
    res: h.get('res'),
  };
}

async function main() {
  await init();
  const opts = hashOptions();
  const preset = wasm.preset_names().includes(opts.preset) ? opts.preset : 'sensors2019';
  const app = wasm.App.from_preset(preset);
  if (opts.res && [...$('resolution').options].some((o) => o.value === opts.res)) $('resolution').value = opts.res;

  const view = new View($('plot'));
  const rgb = wasm.unbounded_rgb();
  const st = {
    nodes: app.nodes(),
    selected: { kind: 'rx', index: 0 },
    selTx: 0,
    selRx: 0,
    mapCanvas: document.createElement('canvas'),
    barCanvas: makeBarCanvas(wasm.colorbar_rgba(256)),
    unboundedColor: `rgb(${rgb[0]},${rgb[1]},${rgb[2]})`,
    values: null,
    image: null,
    range: null,
    res: 256,
    target: null, // { x, y, seed }
    snap: null, // the snapshot of the placed target
    fix: null, // what draw.js shows: the snapshot, or the track frame in tracking mode
    mode: 'snapshot', // or 'tracking'
    overlay: null,
    insetTitle: 'target zoom',
    insetAvoid: [],
    nextSeed: opts.seed,
  };

  const dirty = {};
  let scheduled = false;

  function computeMap() {
    const n = Number($('resolution').value) || 256;
    if (!st.values || st.res !== n) {
      st.values = new Float64Array(n * n);
      st.image = new ImageData(n, n);
      st.mapCanvas.width = n;
      st.mapCanvas.height = n;
      st.res = n;
    }
    const ms = app.compute_map(n, n, st.values);
    st.range = Array.from(wasm.render_map_rgba(st.values, st.image.data));
    st.mapCanvas.getContext('2d').putImageData(st.image, 0, 0);
    const el = $('map-ms');
    el.dataset.ms = String(ms);
    el.dataset.res = `${n}x${n}`;
    el.textContent = `map ${n}×${n}: ${ms.toFixed(1)} ms`;
  }

  function updateProbe() {
    const el = $('probe');
    const x = Number(el.dataset.x);
    const y = Number(el.dataset.y);
    const rmse = app.rmse_at(x, y);
    el.dataset.rmseM = String(rmse);
    el.textContent = `probe (${x}, ${y}) m: ${wasm.format_length(rmse, 4)}`;
  }

  function refresh() {
    scheduled = false;
    const d = { ...dirty };
    for (const k of Object.keys(dirty)) delete dirty[k];
    try {
      if (d.reset) {
        view.fit(app.area());
        st.target = null;
        st.selTx = 0;
        st.selRx = 0;
        st.selected = { kind: 'rx', index: 0 };
      }
      if (d.map) computeMap();
      if (d.geometry) {
        st.nodes = app.nodes();
        updateProbe();
      }
      if (d.target) {
        st.snap = st.target ? app.simulate_fix(st.target.x, st.target.y, st.target.seed) : null;
        panel.showTarget(st.snap);
      }
      if (d.geometry) tracking.rerun();
      if (d.panel) panel.sync();
      const tr = st.mode === 'tracking';
      st.fix = tr ? tracking.frame : st.snap;
      st.overlay = tr ? (c, v) => tracking.overlay(c, v) : null;
      st.insetTitle = tr ? 'EKF zoom · true scale' : 'target zoom';
      st.insetAvoid = tr ? tracking.avoidPoints() : [];
      if (st.mode === 'mtl') mtl.draw(); else drawScene(view, st, wasm);
    } catch (e) {
      showError(`Internal error: ${e && e.message ? e.message : e}`);
      console.error(e);
    }
  }

  /** Marks parts stale and schedules one refresh on the next animation frame. */
  function changed(flags) {
    if (flags.all || flags.reset) Object.assign(dirty, { map: true, geometry: true, target: true, panel: true });
    Object.assign(dirty, flags);
    if (flags.draw) dirty.panel = true;
    if (!scheduled) {
      scheduled = true;
      requestAnimationFrame(refresh);
    }
  }

  const ctx = {
    app, wasm, st, view, changed,
    placeTarget(x, y) {
      st.target = { x, y, seed: st.nextSeed++ };
      changed({ target: true });
    },
    resample() {
      if (st.target) st.target.seed = st.nextSeed++;
      changed({ target: true });
    },
    clearTarget() {
      st.target = null;
      changed({ target: true });
    },
  };
  const panel = new Panel(ctx);
  ctx.panel = panel;
  const tracking = new Tracking(ctx, opts);
  ctx.tracking = tracking;
  const mtl = new Mtl(ctx);
  /** Snapshot view (click to place a target), tracking (animated EKF track + Monte Carlo) or multi-target. */
  const setMode = (mode) => {
    st.mode = ['tracking', 'mtl'].includes(mode) ? mode : 'snapshot';
    document.body.classList.toggle('mode-tracking', st.mode === 'tracking');
    document.body.classList.toggle('mode-mtl', st.mode === 'mtl');
    for (const m of ['snapshot', 'tracking', 'mtl']) $(`mode-${m}`).setAttribute('aria-pressed', String(st.mode === m));
    tracking.setActive(st.mode === 'tracking');
    mtl.setActive(st.mode === 'mtl');
    pointer.showHint();
    changed({ draw: true });
  };
  $('mode-snapshot').addEventListener('click', () => setMode('snapshot'));
  $('mode-tracking').addEventListener('click', () => setMode('tracking'));
  $('mode-mtl').addEventListener('click', () => setMode('mtl'));
  $('preset').value = preset;
  const pointer = attachPointer(ctx);

  view.resize();
  view.fit(app.area());
  new ResizeObserver(() => {
    view.resize();
    changed({ draw: true });
  }).observe($('plot').parentElement);

  if (opts.target) st.target = { x: opts.target.x, y: opts.target.y, seed: st.nextSeed++ };
  Object.assign(dirty, { map: true, geometry: true, target: true, panel: true });
  refresh();
  setMode(opts.mode);
  if (opts.play) tracking.play();

  // Hooks for tests and the console.
  window.app = app;
  window.view = view;
  window.wasm = wasm;
  window.pageState = st;
  window.mapCanvas = st.mapCanvas;
  window.pageIdle = () => !scheduled;
  window.placeTarget = ctx.placeTarget;
  window.tracking = {
    state: () => tracking.state(),
    setMode,
    play: () => tracking.play(),
    pause: () => tracking.pause(),
    seek: (n) => tracking.seek(n),
    restartMc: () => tracking.startMc(),
    mcParams: () => tracking.mc.params,
    mcResult: () => (tracking.mc.result ? JSON.parse(tracking.mc.result) : null),
  };
  window.mtl = {
    state: () => mtl.state(),
    setScene: (s) => mtl.setScene(s),
    pixelFromCentre: (x, y) => mtl.pixelFromCentre(x, y),
    bench: (n) => mtl.bench(n),
    setMode,
  };
  window.importScenarioText = (text, name) => panel.importText(text, name);
  /** Runs the map kernel `n` times at the current resolution: per-run kernel ms (core-timed). */
  window.benchMap = (n = 9) => {
    const r = st.res;
    const buf = new Float64Array(r * r);
    const kernel = [];
    for (let i = 0; i < n; i++) kernel.push(app.compute_map(r, r, buf));
    return { res: r, kernel_ms: kernel };
  };
  document.body.dataset.ready = '1';
}

main().catch((e) => {
  const msg = e && e.message ? e.message : String(e);
  try { showError(`The page could not start: ${msg}`); } catch (_) { /* banner missing */ }
  document.body.dataset.error = msg;
  console.error(e);
});
