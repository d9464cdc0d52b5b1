// The page: loads the wasm core, owns the state, the refresh loop (one redraw per animation frame
// at most) and the mode switch between the three views: snapshot (map.js), tracking
// (tracking.js) and multi-target (mtl.js). All numbers come from the core; JavaScript routes
// events and draws. Loaded by main.js.

import init, * as wasm from '../pkg/scatterloc.js';
import { $, errorText, showError } from './dom.js';
import { registerHooks } from './hooks.js';
import { View } from './view.js';
import { MapView } from './map.js';
import { Panel } from './panel.js';
import { attachPointer } from './interact.js';
import { Tracking } from './tracking.js';
import { Mtl } from './mtl.js';

const MODES = ['snapshot', 'tracking', 'mtl'];

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
    mode: MODES.includes(h.get('mode')) ? h.get('mode') : 'snapshot',
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
    seed: int('seed') ?? 1,
    res: h.get('res'),
  };
}

export async function start() {
  await init();
  const opts = hashOptions();
  const preset = wasm.preset_names().includes(opts.preset) ? opts.preset : 'sensors2019';
  const app = wasm.App.from_preset(preset);
  if (opts.res && [...$('resolution').options].some((o) => o.value === opts.res)) $('resolution').value = opts.res;

  const view = new View($('plot'));
  const st = {
    nodes: app.nodes(),
    selected: { kind: 'rx', index: 0 },
    selTx: 0,
    selRx: 0,
    target: null, // { x, y, seed }
    snap: null, // the snapshot of the placed target
    fix: null, // what map.js shows: the snapshot, or the track frame in tracking mode
    mode: 'snapshot', // or 'tracking', 'mtl'
    overlay: null,
    insetTitle: 'target zoom',
    insetAvoid: [],
    nextSeed: opts.seed,
    // + the map's fields (map.js)
  };

  const dirty = {};
  let scheduled = false;

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
      if (d.map) map.compute();
      if (d.geometry) {
        st.nodes = app.nodes();
        map.probe();
      }
      if (d.target) panel.showTarget(map.simulateTarget());
      if (d.geometry) tracking.rerun();
      if (d.panel) panel.sync();
      const tr = st.mode === 'tracking';
      st.fix = tr ? tracking.frame : st.snap;
      st.overlay = tr ? (c, v) => tracking.overlay(c, v) : null;
      st.insetTitle = tr ? 'EKF zoom · true scale' : 'target zoom';
      st.insetAvoid = tr ? tracking.avoidPoints() : [];
      if (st.mode === 'mtl') mtl.draw(); else map.draw();
    } catch (e) {
      showError(`Internal error: ${errorText(e)}`);
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

  const ctx = { app, wasm, st, view, changed };
  const map = new MapView(ctx);
  ctx.placeTarget = (x, y) => map.placeTarget(x, y);
  ctx.resample = () => map.resample();
  ctx.clearTarget = () => map.clearTarget();
  const panel = new Panel(ctx);
  ctx.panel = panel;
  const tracking = new Tracking(ctx, opts);
  ctx.tracking = tracking;
  const mtl = new Mtl(ctx);
  /** Snapshot view (click to place a target), tracking (animated EKF track + Monte Carlo) or multi-target. */
  const setMode = (mode) => {
    st.mode = MODES.includes(mode) ? mode : 'snapshot';
    document.body.classList.toggle('mode-tracking', st.mode === 'tracking');
    document.body.classList.toggle('mode-mtl', st.mode === 'mtl');
    for (const m of MODES) $(`mode-${m}`).setAttribute('aria-pressed', String(st.mode === m));
    tracking.setActive(st.mode === 'tracking');
    mtl.setActive(st.mode === 'mtl');
    pointer.showHint();
    changed({ draw: true });
  };
  for (const m of MODES) $(`mode-${m}`).addEventListener('click', () => setMode(m));
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

  registerHooks({
    app, wasm, view, st, setMode, panel, tracking, mtl,
    isIdle: () => !scheduled,
    placeTarget: ctx.placeTarget,
  });
}
