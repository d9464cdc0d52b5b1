// The page: loads the wasm core, owns the state, the refresh loop (one redraw per animation frame
// at most) and the mode switch between the four views (views.js VIEWS): snapshot (map.js, with the Plan
// panel of plan.js), tracking (tracking.js), multi-target (mtl.js) and channel (channel.js);
// reads its options, and a shared scenario, from the URL hash and writes them back for "Copy
// link" (share.js). All numbers come from the core; JavaScript routes events and draws. Loaded
// by main.js.

import init, * as wasm from '../pkg/scatterloc.js';
import { $, clip, decimal, decimalIn, errorText, showError } from './dom.js';
import { decodeScenario, decodeState, viewLink } from './share.js';
import { attachState } from './state.js';
import { registerHooks } from './hooks.js';
import { View } from './view.js';
import { MapView, registerMapState } from './map.js';
import { Doppler, registerDopplerState } from './doppler.js';
import { Panel, registerScenarioState } from './panel.js';
import { attachPointer, hitNode } from './interact.js';
import { attachKeyboard } from './keyboard.js';
import { FILTERS, SEED_RANGE, Tracking, registerTrackingState } from './tracking.js';
import { Mtl, registerMtlState } from './mtl.js';
import { Plan, registerPlanState } from './plan.js';
import { FigureExport } from './export.js';
import { Zoomer, registerViewState } from './zoom.js';
import { setLinkColors } from './draw.js';
import { Channel, registerChannelState } from './channel.js';
import { registerColoursState } from './colour-lock.js';
import { VIEWS, registerModeState } from './views.js';
import { homeWithNodes } from './outside.js';
import { attachHelp } from './help.js';
import { attachTheme } from './theme.js';

/**
 * Every option the page reads from the URL hash (anything else is named in the banner as unknown):
 * `#preset=iclgnss2019&target=6,4&seed=3&res=256` (snapshot); tracking: `#mode=tracking&track=II
 * &step=45&play=1&runs=200&ex=100&tseed=1&dt=0.1&speed=1&custom=x0,y0,x1,y1&filter=pf
 * &particles=1000&filters=ekf,ukf,pf` (the animated filter, the particle count and the Monte
 * Carlo's filters); multi-target: `#mode=mtl`; a shared view ("Copy link"): `view=x0,x1,y0,y1`
 * (the map's zoomed window, m), `roi=x0,x1,y0,y1` (the Plan panel's region of interest, m) and
 * the scenario as `scenario=<base64url of its JSON>` or `z=<base64url of its raw-deflated JSON>`
 * (share.js; a scenario replaces the preset); `probe=x,y` pins the status bar's probe at (x, y) m.
 */
const KNOWN = ['mode', 'preset', 'res', 'target', 'seed', 'view', 'roi', 'scenario', 'z', 'track', 'step',
  'play', 'runs', 'ex', 'tseed', 'dt', 'speed', 'filter', 'particles', 'filters', 'custom',
  'state', 'zstate']; // state, zstate: the rest of the page state (state.js; "Copy link" writes it)
KNOWN.push('probe'); // the pinned probe (map.js pinProbe)

/**
 * The URL hash -> {opts, errors}. Every option is parsed strictly with the panel's own ranges:
 * a choice must be one of the panel's choices (its <select>'s values: `res`, `runs`,
 * `ex`, `dt`, `speed`, `filter`, `particles`), a number a strict decimal (dom.js `decimal`) in
 * the range the panel or the core uses (`step`: the core's track_field_ranges; `seed`, `tseed`:
 * the seed inputs' range; `target`, `custom`: the core's coordinate range, check_point; `view`,
 * `roi`: the core's rule for areas, check_rect), `play` 0 or 1, `filters` a list of distinct ekf, ukf, pf. A bad, repeated or
 * unknown option is left at its default and reported in `errors` (naming the option, the value
 * given and what is allowed); the rest of the link still applies. The scenario, the window
 * (within the zoom and pan limits of the scenario's area, View.setWindow) and the ROI (inside
 * the area) are judged in start().
 */
function hashOptions(presets) {
  const h = new URLSearchParams(location.hash.slice(1));
  const errors = [];
  const bad = new Set(); // options already reported
  const report = (k, message) => {
    bad.add(k);
    errors.push(`URL option ${message}`);
  };
  for (const k of new Set(h.keys())) {
    if (!KNOWN.includes(k)) report(k, `${clip(k)}: unknown (known options: ${KNOWN.join(', ')})`);
    else if (h.getAll(k).length > 1) report(k, `${k}: given ${h.getAll(k).length} times (at most once)`);
  }
  const read = (k, parse) => {
    const t = h.get(k);
    if (t === null || bad.has(k)) return undefined;
    try {
      return parse(t);
    } catch (e) {
      report(k, errorText(e));
      return undefined;
    }
  };
  const oneOf = (k, values) => read(k, (t) => {
    if (!values.includes(t)) throw new Error(`${k}: "${clip(t)}" is not one of ${values.join(', ')}`);
    return t;
  });
  // A choice of the panel: one of its <select>'s values, written exactly as there.
  const option = (k, id) => oneOf(k, [...$(id).options].map((o) => o.value));
  const numbers = (k, n) => read(k, (t) => {
    const parts = t.split(',');
    if (parts.length !== n) throw new Error(`${k}: "${clip(t)}" is not ${n} comma-separated numbers`);
    return parts.map((p, i) => decimal(p, `${k}[${i}]`));
  });
  // n numbers that the core then checks (one definition; its errors name `${k}.x` and so on).
  const checked = (k, n, check) => {
    const v = numbers(k, n);
    return v === undefined ? undefined : read(k, () => {
      check(v);
      return v;
    });
  };
  // The step index's range is the core's (MAX_TRACK_STEPS, one definition).
  const stepRange = JSON.parse(wasm.track_field_ranges()).step;
  const target = checked('target', 2, ([x, y]) => wasm.check_point('target', x, y));
  const probe = checked('probe', 2, ([x, y]) => wasm.check_point('probe', x, y));
  const custom = checked('custom', 4, ([x0, y0, x1, y1]) => {
    wasm.check_point('custom.start', x0, y0);
    wasm.check_point('custom.end', x1, y1);
  });
  const rect = (k) => checked(k, 4, (r) => wasm.check_rect(k, ...r));
  const scenarioKeys = ['z', 'scenario'].filter((k) => h.has(k) && !bad.has(k));
  if (scenarioKeys.length > 1) report('scenario', 'z and scenario: both given (one scenario at most)');
  const opts = {
    mode: oneOf('mode', VIEWS) ?? 'snapshot',
    track: oneOf('track', [...$('track-kind').options].map((o) => o.value)),
    step: read('step', (t) => decimalIn(t, 'step', { min: stepRange[0], max: stepRange[1], integer: true })),
    play: oneOf('play', ['0', '1']) === '1',
    runs: option('runs', 'mc-runs'),
    ex: option('ex', 'track-ex'),
    tseed: read('tseed', (t) => decimalIn(t, 'tseed', SEED_RANGE)),
    dt: option('dt', 'track-dt'),
    speed: option('speed', 'track-speed'),
    filter: option('filter', 'track-filter'),
    particles: option('particles', 'track-particles'),
    filters: read('filters', (t) => {
      const names = t.split(',');
      const wrong = names.find((n) => !FILTERS.includes(n));
      if (wrong !== undefined) throw new Error(`filters: "${clip(wrong)}" is not one of ${FILTERS.join(', ')}`);
      const twice = names.find((n, i) => names.indexOf(n) !== i);
      if (twice !== undefined) throw new Error(`filters: "${twice}" is given twice (distinct filters of ${FILTERS.join(', ')})`);
      return names;
    }),
    custom: custom ? { x0: custom[0], y0: custom[1], x1: custom[2], y1: custom[3] } : null,
    preset: oneOf('preset', presets),
    target: target ? { x: target[0], y: target[1] } : null,
    probe: probe ? { x: probe[0], y: probe[1] } : null,
    seed: read('seed', (t) => decimalIn(t, 'seed', SEED_RANGE)) ?? 1,
    res: option('res', 'resolution'),
    roi: rect('roi'),
    view: rect('view'),
    scenario: scenarioKeys.length === 1 ? [scenarioKeys[0], h.get(scenarioKeys[0])] : null,
    state: null,
  };
  const stateKeys = ['zstate', 'state'].filter((k) => h.has(k) && !bad.has(k));
  if (stateKeys.length > 1) report('state', 'zstate and state: both given (one page state at most)');
  else if (stateKeys.length === 1) opts.state = [stateKeys[0], h.get(stateKeys[0])];
  return { opts, errors };
}

export async function start() {
  // Compiled once here and handed to every replaceable worker (workers.js), so a fresh worker
  // starts in milliseconds.
  const wasmUrl = new URL('../pkg/scatterloc_bg.wasm', import.meta.url);
  const module = await WebAssembly.compile(await (await fetch(wasmUrl)).arrayBuffer());
  await init({ module_or_path: module });
  setLinkColors(wasm.link_rgb());
  const { opts, errors } = hashOptions(wasm.preset_names());
  const preset = opts.preset ?? 'sensors2019';
  const app = wasm.App.from_preset(preset);
  let shared = false;
  if (opts.scenario) {
    // A shared scenario; a bad one is named in the banner and the preset stays.
    const [key, value] = opts.scenario;
    try {
      app.set_scenario_json(await decodeScenario(key, value));
      shared = true;
    } catch (e) {
      errors.push(`URL option ${key}: ${errorText(e)}`);
    }
  }
  if (opts.res) $('resolution').value = opts.res;

  const view = new View($('plot'));
  const st = {
    nodes: app.nodes(),
    selected: { kind: 'rx', index: 0 },
    selTx: 0,
    selRx: 0,
    target: null, // { x, y, seed }
    snap: null, // the snapshot of the placed target
    fix: null, // what map.js shows: the snapshot, or the track frame in tracking mode
    mode: 'snapshot', // one of VIEWS (views.js)
    overlay: null,
    insetTitle: 'target zoom',
    insetAvoid: [],
    nextSeed: opts.seed,
    probe: opts.probe, // the pinned probe {x, y} m, or null (map.js)
    refreshLog: [], // [{ms, mapMs, res, dragging}] of the last 64 refreshes (main thread)
    // + the map's fields (map.js)
  };

  const dirty = {};
  let scheduled = false;

  /**
   * The view's home: the area, widened to show nodes outside it (outside.js: a warning names
   * them; the area is drawn as a dashed outline). Returns homeWithNodes' {home, outline, warning}.
   */
  function setHomeFor() {
    const h = homeWithNodes(app.area(), app.nodes());
    view.setHome(h.home);
    st.areaOutline = h.outline;
    st.outsideWarning = h.warning;
    return h;
  }

  function refresh() {
    scheduled = false;
    const d = { ...dirty };
    for (const k of Object.keys(dirty)) delete dirty[k];
    const t0 = performance.now();
    const dragging = !!d.dragging && !d.dragEnd;
    try {
      if (d.reset) {
        const home = setHomeFor();
        if (home.warning) showError(home.warning);
        view.reset();
        zoom.show();
        st.target = null;
        st.selTx = 0;
        st.selRx = 0;
        st.selected = { kind: 'rx', index: 0 };
        plan.onReset();
      }
      if (d.map) map.compute(dragging);
      if (d.geometry) {
        st.nodes = app.nodes();
        map.probe();
      }
      if (d.target) panel.showTarget(map.simulateTarget());
      if (d.geometry) tracking.rerun();
      if (d.panel) panel.sync();
      const tr = st.mode === 'tracking';
      st.fix = tr ? tracking.frame : st.snap;
      st.overlay = tr ? (c, v) => tracking.overlay(c, v)
        : plan.showsRoi() ? (c, v) => plan.overlay(c, v) : null;
      st.insetTitle = tr ? `${tracking.filterName()} zoom 1:1` : 'target zoom';
      st.insetAvoid = tr ? tracking.avoidPoints() : map.avoidPoints();
      if (st.mode === 'channel') {
        // The channel view (channel.js): its track layer, no snapshot target.
        st.fix = null;
        st.overlay = (c, v) => channel.overlayLayer(c, v);
        st.insetAvoid = [];
      }
      if (st.mode === 'mtl') mtl.draw(); else map.draw();
    } catch (e) {
      showError(`Internal error: ${errorText(e)}`);
      console.error(e);
    }
    const el = $('map-ms');
    st.refreshLog.push({
      ms: performance.now() - t0, map: !!d.map, mapMs: d.map ? Number(el.dataset.ms) : null,
      res: d.map ? el.dataset.res : null, dragging,
    });
    if (st.refreshLog.length > 64) st.refreshLog.shift();
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

  const ctx = { app, wasm, module, st, view, changed };
  const map = new MapView(ctx);
  const doppler = new Doppler(ctx); // the Doppler control and the velocity map (doppler.js)
  ctx.doppler = doppler;
  ctx.placeTarget = (x, y) => map.placeTarget(x, y);
  ctx.resample = () => map.resample();
  ctx.clearTarget = () => map.clearTarget();
  ctx.pinProbe = (x, y) => map.pinProbe(x, y);
  $('probe-clear').addEventListener('click', () => map.pinProbe(null));
  const panel = new Panel(ctx);
  ctx.panel = panel;
  const tracking = new Tracking(ctx, opts);
  ctx.tracking = tracking;
  const mtl = new Mtl(ctx);
  ctx.mtl = mtl;
  const plan = new Plan(ctx);
  ctx.plan = plan;
  const figures = new FigureExport(ctx); // "Save figure" (export.js)
  ctx.figures = figures;
  const channel = new Channel(ctx); // the channel view (channel.js)
  ctx.channel = channel;
  // Zoom and pan in the three views (zoom.js); the press handlers below pan on empty map.
  const zoom = new Zoomer(ctx, mtl, (p) => (st.mode === 'mtl' ? !!mtl.hit(p) : !!hitNode(view, st.nodes, p)));
  ctx.zoom = zoom;
  zoom.cancelPress.push(() => mtl.cancelPress());
  /**
   * Snapshot view (click to place a target), tracking (animated filter track + Monte Carlo),
   * multi-target or channel (recordings to a track).
   */
  const setMode = (mode) => {
    st.mode = VIEWS.includes(mode) ? mode : 'snapshot';
    document.body.classList.toggle('mode-tracking', st.mode === 'tracking');
    document.body.classList.toggle('mode-mtl', st.mode === 'mtl');
    document.body.classList.toggle('mode-channel', st.mode === 'channel');
    for (const m of VIEWS) $(`mode-${m}`).setAttribute('aria-pressed', String(st.mode === m));
    tracking.setActive(st.mode === 'tracking');
    mtl.setActive(st.mode === 'mtl');
    channel.setActive(st.mode === 'channel');
    figures.setMode(st.mode);
    doppler.sync();
    zoom.show();
    if (st.mode !== 'snapshot') {
      plan.cancel('view changed');
      plan.arm(false);
    }
    pointer.showHint();
    changed({ draw: true });
  };
  for (const m of VIEWS) $(`mode-${m}`).addEventListener('click', () => setMode(m));
  $('preset').value = shared ? '' : preset;
  const pointer = attachPointer(ctx);
  attachKeyboard(ctx, mtl);
  ctx.showHint = () => pointer.showHint();
  zoom.onFit.push(() => pointer.undoDoubleClick());
  const help = attachHelp();
  const theme = attachTheme((now) => {
    if (now) refresh(); else changed({ draw: true });
    tracking.mc.drawChart();
    plan.drawChart();
  });

  view.resize();
  const home0 = setHomeFor();
  if (home0.warning) errors.push(home0.warning);
  if (opts.view) {
    try {
      view.setWindow(opts.view);
    } catch (e) {
      errors.push(`URL option view: ${errorText(e)}`);
    }
  }
  new ResizeObserver(() => {
    view.resize();
    changed({ draw: true });
  }).observe($('plot').parentElement);
  // A new devicePixelRatio (browser zoom, another screen) without a new CSS size: redraw sharp.
  const watchDpr = () => matchMedia(`(resolution: ${window.devicePixelRatio}dppx)`)
    .addEventListener('change', () => {
      view.resize();
      changed({ draw: true });
      // The charts' CSS size is unchanged, so their ResizeObservers stay silent: redraw them too.
      tracking.mc.drawChart();
      plan.drawChart();
      watchDpr();
    }, { once: true });
  watchDpr();

  if (opts.roi) {
    try {
      plan.setRoi(opts.roi);
      plan.setOpen(true);
    } catch (e) {
      errors.push(`URL option roi: ${errorText(e)}`);
    }
  }
  if (opts.target) st.target = { x: opts.target.x, y: opts.target.y, seed: st.nextSeed++ };
  Object.assign(dirty, { map: true, geometry: true, target: true, panel: true });
  refresh();
  $('loading').hidden = true; // the first map is drawn
  setMode(opts.mode);
  // The page state (state.js): saved and opened as a file, carried by the link, undo/redo. Each
  // view registers its own section; they are checked and applied in this order.
  const homeFor = setHomeFor;
  registerChannelState();
  registerColoursState(map.lock);
  registerScenarioState({ app, wasm, st, plan, ctx, homeFor });
  registerMapState(ctx); // grid, target
  registerDopplerState(doppler, ctx);
  registerPlanState(plan, ctx);
  registerTrackingState(tracking, wasm);
  registerMtlState(mtl, wasm);
  registerViewState({ app, wasm, st, view, mtl, plan, tracking, zoom, ctx, homeFor });
  registerModeState(st, setMode);
  const pageState = attachState({ app, panel, tracking, plan, ctx });
  if (opts.state) {
    const [key, value] = opts.state;
    try {
      const bad = pageState.openLink(await decodeState(key, value));
      if (bad) errors.push(`URL option ${key}: ${bad}`);
    } catch (e) {
      errors.push(`URL option ${key}: ${errorText(e)}`);
    }
  }
  if (opts.play) tracking.play();
  if (errors.length) showError(errors.join(' · '));

  /** The link to this view: mode, map grid, zoomed window, target, ROI and the scenario (share.js). */
  const link = () => viewLink({
    mode: st.mode,
    res: $('resolution').value,
    target: st.target,
    roi: plan.roi,
    window: view.zoomed() ? Array.from(view.area) : null,
    scenario: app.scenario_json(),
    state: pageState.linkState(),
    checkState: (text) => pageState.checkLink(text), // the read-back: the link's state restores
  });
  $('share-copy').addEventListener('click', () => copyLink(link, () => panel.exportJson()));
  $('share-close').addEventListener('click', () => { $('share').hidden = true; });

  registerHooks({
    app, wasm, view, st, setMode, panel, tracking, mtl, map, plan, link, figures, zoom, channel, doppler,
    isIdle: () => !scheduled && !map.busy(),
    pageState: pageState.hooks(),
    help, theme,
    placeTarget: ctx.placeTarget,
  });
}

/**
 * "Copy link": shows the link in the read-only field (selected, for copying by hand) and writes
 * it to the clipboard where the browser allows it. A scenario too large for a link (share.js
 * viewLink's `tooLarge`) is said so in the bar, with a button saving the scenario file
 * (`save`, the panel's Export) instead.
 */
async function copyLink(link, save) {
  const field = $('share-url');
  const saveButton = $('share-save');
  let url;
  try {
    url = await link();
  } catch (e) {
    if (!e || !e.tooLarge) {
      showError(`Copy link: ${errorText(e)}`);
      return;
    }
    field.value = '';
    field.hidden = true;
    saveButton.hidden = false;
    saveButton.onclick = save;
    $('share').hidden = false;
    $('share-note').textContent = `No link: ${errorText(e)}.`;
    saveButton.focus();
    return;
  }
  field.hidden = false;
  saveButton.hidden = true;
  field.value = url;
  $('share').hidden = false;
  $('share-note').textContent = '';
  field.focus();
  field.select();
  field.scrollLeft = 0;
  let note = 'select and copy it';
  if (navigator.clipboard && window.isSecureContext) {
    try {
      await navigator.clipboard.writeText(url);
      note = 'copied to the clipboard';
    } catch (_) {
      note = 'the clipboard refused it: select and copy it';
    }
  }
  $('share-note').textContent = note;
}
