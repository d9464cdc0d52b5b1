// Every hook the end-to-end tests (tests/e2e.rs, tests/e2e/*.rs) and the console use, in one
// place: the `window` names below, and the body's data-ready / data-error attributes. The names
// are read by the tests; keep them.
//
//   window.__consoleErrors   every console.error, page error and unhandled rejection (text)
//   window.app               the core's App (scenario, nodes, map kernel)
//   window.view              the map view's pixel <-> metre transform (View)
//   window.wasm              the wasm module
//   window.pageState         the page state (mode, nodes, target, …)
//   window.mapCanvas         the CRLB map image (one pixel per cell)
//   window.pageIdle()        true when no redraw and no full-resolution map (worker) is pending
//   window.refreshLog()      the last 64 refreshes: [{ms (main thread), map, mapMs, res, dragging}]
//   window.mapState()        {res, full, source, ms, busy, restarts, nsPerCellLink} of the map
//   window.placeTarget(x, y) places the snapshot target (m)
//   window.tracking          {state, setMode, play, pause, seek, restartMc, mcParams, mcResult, trackData}
//   window.mtl               {state, setScene, pixelFromCentre, bench, setMode}
//   window.plan              the Plan panel: state() {state: 'idle' | 'running' | 'done' | 'error',
//                            evaluations, budget, messages (progress messages received), improvements
//                            (layouts applied), points (history), chartPoints (drawn), gliding,
//                            wallMs (Optimize to result), workerMs, stopped (reason), request,
//                            applied (the last layout applied, JSON), undo, roi, roiCustom, open,
//                            drawing, error}; start(overrides?) -> null | message (the panel's
//                            request with `overrides`' fields); stop(); undo(); result() (plan.json
//                            of the last finished plan, or null); setRoi([x0, x1, y0, y1] | null)
//                            -> null | message; setOpen(bool); armRoi(bool) ("Draw ROI")
//   window.shareLink()       Promise of the link to this view ("Copy link" shows the same in #share-url)
//   window.importScenarioText(text, name)  loads scenario JSON as an imported file would
//   window.benchMap(n)       n runs of the map kernel at the current resolution: core-timed ms
//   window.figureExport      "Save figure" (export.js): last() -> {name, type, size, ms, href (the
//                            download link's blob URL), mode, what, format, partial (the RMSE
//                            chart of a running study: "partial: 64 of 200 runs", else '')} | null; save();
//                            setDryRun(bool) (build the link without clicking it)
//   window.zoom              zoom and pan (zoom.js): state() -> {window, home ([x0, x1, y0, y1] m),
//                            zoomed, factor, rect (the plot, CSS px), gestures, ticks {x, y} and
//                            scaleBar {length_m, label} of the last frame, level}; reset();
//                            hitAt(x, y) (an object under canvas pixel x, y: a press drags it);
//                            toMetre(x, y) (canvas pixel -> {x, y} m in the view on screen)
//   window.channel           the channel view (channel.js): state() -> {running, progress, runs,
//                            stopped, status, statusState, error, recording, calibration, truth,
//                            steps, step, t_s, playing, drawn (what the map layer drew: {step,
//                            estimate, sigma, links, truth, track_points, track_runs, segment}),
//                            cursorX, delayBox, errorBox, segments (TRACK.json's: {first, last,
//                            t_first_s, t_last_s, end}), segmentMarks (drawn over the error
//                            chart: {gaps, losses: [{x, t_s, end, label}], starts}), statics
//                            ({source, snapshots, statics, delay_reference} of the result),
//                            links, timings, wallMs, workerMs, settings}; texts()
//                            (the result's TRACK.json, EST.json, figure and error texts, or null);
//                            truthStates() (the truth file's states, or null);
//                            seek(k); play(); pause(); settings() / applySettings(obj)
//                            (channelSettings / applyChannelSettings)
//   window.pictures          map.js hooks(): getColourRange(), setColourRange(obj), colourBar()
//                            (last frame's {min_m, max_m, locked, ticks, marks, bar}), inset()
//                            ({closed, moved, box}), baselines() (clipped segments, CSS px),
//                            range(); data {text(what, format), save(), last(), setDryRun};
//                            outsideWarning() (nodes outside the area, outside.js)
//   window.getColourRange() / setColourRange(obj)  the colour lock (colour-lock.js; the latter
//                            throws a ColourRangeError)
//   window.pageStateModel    the page state (state.js): capture() (the whole state object);
//                            restore(obj) -> null | the banner's message; history() -> {index,
//                            length, pending, busy}; undo(); redo(); dirty(); lastSaved() -> {name,
//                            text} of the last "Save state"; setDryRun(bool)
//   window.doppler           the Doppler control (doppler.js): state() -> {on, shown, kernel ('delay' |
//                            'doppler': the map's), settings, error, velocityRange, colourBar (the
//                            velocity map's)}; maps() -> {kernel, res, window, position, velocity
//                            (the last maps' values, or null)}
//   window.help              the Help dialog (help.js): open(), close(), isOpen()
//   window.theme             the colour theme (theme.js): get() -> 'dark' | 'light'; set('dark' |
//                            'light' | null (follow the system)); colors() (the canvas' colours)
//   body[data-ready='1']     the page is up;  body[data-error]  it failed (the message)

/**
 * Records every error from now on in `window.__consoleErrors` and marks the body with the first
 * uncaught one, so the tests fail fast with the message. main.js calls it before loading the page.
 */
export function captureErrors() {
  window.__consoleErrors = [];
  const orig = console.error.bind(console);
  console.error = (...args) => {
    window.__consoleErrors.push(args.map(String).join(' '));
    orig(...args);
  };
  const fail = (msg) => {
    window.__consoleErrors.push(msg);
    markFailed(msg);
  };
  addEventListener('error', (e) => fail(e.message ? `error: ${e.message}`
    : `failed to load ${(e.target && (e.target.src || e.target.href)) || 'a resource'}`), true);
  addEventListener('unhandledrejection', (e) => fail(`unhandledrejection: ${(e.reason && e.reason.message) || e.reason}`));
}

/** body[data-error] = the message (the tests stop waiting on it). */
export function markFailed(msg) {
  if (document.body) document.body.dataset.error = msg;
  else addEventListener('DOMContentLoaded', () => { document.body.dataset.error = msg; });
}

/**
 * Registers the window hooks once the page is up, then sets body[data-ready].
 * @param {object} p - {app, wasm, view, st, isIdle, setMode, panel, tracking, mtl, map, plan, link,
 *   placeTarget, figures, zoom}
 */
export function registerHooks(p) {
  const { app, st, tracking, mtl } = p;
  Object.assign(window, {
    app,
    view: p.view,
    wasm: p.wasm,
    pageState: st,
    mapCanvas: st.mapCanvas,
    pageIdle: p.isIdle,
    refreshLog: () => st.refreshLog.slice(),
    mapState: () => {
      const d = document.getElementById('map-ms').dataset;
      return {
        res: d.res, full: d.full, source: d.source, ms: Number(d.ms), busy: p.map.busy(),
        restarts: p.map.worker.restarts, nsPerCellLink: p.map.nsPerCellLink,
      };
    },
    placeTarget: p.placeTarget,
    tracking: {
      state: () => tracking.state(),
      setMode: p.setMode,
      play: () => tracking.play(),
      pause: () => tracking.pause(),
      seek: (n) => tracking.seek(n),
      restartMc: () => tracking.startMc(),
      mcParams: () => tracking.mc.params,
      mcResult: () => (tracking.mc.result ? JSON.parse(tracking.mc.result) : null),
      trackData: () => tracking.data,
    },
    mtl: {
      state: () => mtl.state(),
      setScene: (s) => mtl.setScene(s),
      pixelFromCentre: (x, y) => mtl.pixelFromCentre(x, y),
      bench: (n) => mtl.bench(n),
      setMode: p.setMode,
    },
    plan: {
      state: () => p.plan.state(),
      start: (overrides) => p.plan.start(overrides),
      stop: () => p.plan.stop(),
      undo: () => p.plan.undo(),
      result: () => p.plan.result,
      setRoi: (r) => {
        try {
          p.plan.setRoi(r);
          return null;
        } catch (e) {
          return e.message;
        }
      },
      setOpen: (on) => p.plan.setOpen(on),
      armRoi: (on) => p.plan.arm(on),
    },
    shareLink: () => p.link(),
    pageStateModel: p.pageState,
    figureExport: {
      last: () => p.figures.lastInfo(),
      save: () => p.figures.save(),
      setDryRun: (on) => { p.figures.dryRun = !!on; },
    },
    zoom: {
      state: () => p.zoom.state(),
      reset: () => p.zoom.reset(),
      hitAt: (x, y) => !!p.zoom.hitAt({ x, y }),
      toMetre: (x, y) => p.zoom.view().toMetre(x, y),
    },
    help: p.help,
    theme: p.theme,
    doppler: p.doppler.hooks(),
    importScenarioText: (text, name) => p.panel.importText(text, name),
    channel: {
      state: () => p.channel.state(),
      texts: () => p.channel.texts(),
      truthStates: () => (p.channel.truth ? p.channel.truth.data.states : null),
      seek: (k) => p.channel.seek(k),
      play: () => p.channel.play(),
      pause: () => p.channel.pause(),
      settings: () => p.channel.settings(),
      applySettings: (obj) => p.channel.applySettings(obj),
    },
    // Pictures (map.js hooks(), data-export.js): colour range, inset, baselines, data export.
    pictures: { ...p.map.hooks(), data: p.figures.data.hooks(), outsideWarning: () => st.outsideWarning || '' },
    getColourRange: () => p.map.lock.get(),
    setColourRange: (obj) => p.map.lock.set(obj),
    benchMap: (n = 9) => {
      const r = st.res;
      const buf = new Float64Array(r * r);
      const kernel = [];
      for (let i = 0; i < n; i++) kernel.push(app.compute_map(r, r, buf));
      return { res: r, kernel_ms: kernel };
    },
  });
  document.body.dataset.ready = '1';
}
