// The snapshot (CRLB map) view: the core's RMSE-bound map over the window shown (the area, or the
// zoomed / panned part of it, zoom.js), the probe read-out, the placed target's simulated
// snapshot (LM fix vs CRLB) and the drawing of the whole scene: heatmap, colour bar, scale bar,
// links, nodes, the target's iso-delay ellipses and its zoom inset. The
// tracking view draws through the same scene (its frame is snapshot-shaped, plus an overlay).
// Every number comes from the wasm core.
//
// The map's cost is bounded per frame: the page learns its own kernel time per cell·link; a map
// predicted to fit FRAME_MS is computed on the main thread at the chosen resolution. A costlier
// one is computed at once at the largest resolution that fits (shown as such in #map-ms) and,
// unless a drag is going on, at full resolution in a worker (map-worker.js; a new edit replaces
// it, workers.js); a drag's end asks for the full map. With Doppler on (doppler.js, ctx.doppler)
// the same logic runs the Doppler kernel (the position bound into st.values, the velocity bound
// into st.velValues), its cost per cell·link learnt apart from the delay kernel's.

import { $, fixed, showError } from './dom.js';
import { Zoom } from './view.js';
import { JobWorker } from './workers.js';
import { C, FONT, FONT_B, FULL, clipTo, cross, drawAxes, drawNodes, drawScaleBar, ellipsePath, fitText, haloText, linkColor, polyline } from './draw.js';
import { ColourLock } from './colour-lock.js';
import { HARD, InsetControls, chooseBox } from './inset.js';
import { registerSection } from './state.js';
import { choice, fields, number } from './state-fields.js';
import { SEED_RANGE } from './tracking.js';

/** Main-thread budget of the map kernel per refresh, ms (about 60 % of a 60 Hz frame). */
const FRAME_MS = 10;
/** Smallest resolution of a reduced map (cells per side). */
const MIN_RES = 8;

export class MapView {
  /** @param {object} ctx - {app, wasm, module, st, view, changed}. */
  constructor(ctx) {
    this.ctx = ctx;
    const { wasm } = ctx;
    const rgb = wasm.unbounded_rgb();
    Object.assign(ctx.st, {
      mapCanvas: document.createElement('canvas'), // one pixel per cell, row 0 = lowest y
      barCanvas: makeBarCanvas(wasm.colorbar_rgba(256)),
      unboundedColor: `rgb(${rgb[0]},${rgb[1]},${rgb[2]})`,
      values: null,
      velValues: null, // the velocity bound (m/s) of a map with Doppler, else null (doppler.js)
      mapKernel: 'delay', // the kernel of st.values: 'delay' or 'doppler'
      mapWindow: null, // the window [x0, x1, y0, y1] (m) the values were computed for
      image: null,
      range: null,
      clamped: [0, 0], // cells below / above a locked colour range (colour-lock.js)
      res: 256,
    });
    // "Lock colours" (colour-lock.js): a new range recolours the map without recomputing it.
    this.lock = new ColourLock(ctx, () => {
      if (ctx.st.values && ctx.st.image) this.paint();
      ctx.changed({ draw: true });
    });
    ctx.st.colourLock = this.lock;
    // The zoom inset's drag handle, × and "Show zoom inset" (inset.js).
    ctx.st.insetControls = new InsetControls(ctx.view.canvas, () => ctx.changed({ draw: true }));
    this.costs = {}; // per kernel ('delay', 'doppler'): {ns (per cell·link), links}, learnt from every map
    this.worker = new JobWorker(new URL('./map-worker.js', import.meta.url), ctx.module, {
      staleMs: 0,
      onResult: (m) => this.receive(m),
      onError: (message) => showError(`CRLB map: ${message}`),
    });
  }

  /** The resolution chosen in #resolution (cells per side). */
  fullRes() {
    return Number($('resolution').value) || 256;
  }

  /** The Doppler settings of the next map (doppler.js job(): null for the delay-only map). */
  dopplerJob() {
    return this.ctx.doppler ? this.ctx.doppler.job() : null;
  }

  /** The kernel cost per cell·link learnt for the kernel of the next map, ns (null: none yet). */
  get nsPerCellLink() {
    const c = this.costs[this.dopplerJob() ? 'doppler' : 'delay'];
    return c ? c.ns : null;
  }

  /** Predicted main-thread kernel time of an n × n map with `links` links, ms. */
  predictMs(n, links) {
    return (n * n * links * this.nsPerCellLink) / 1e6;
  }

  /**
   * Recomputes the map (see the file comment). `dragging`: a drag is going on (no worker job:
   * the drag's end asks again).
   */
  compute(dragging = false) {
    const { app } = this.ctx;
    const n = this.fullRes();
    const links = app.link_count();
    const doppler = this.dopplerJob();
    const ns = this.nsPerCellLink;
    // The probe reads the bound of the map now wanted (with Doppler or not, its settings).
    this.probe();
    if (ns === null || this.predictMs(n, links) <= FRAME_MS) {
      this.worker.cancel();
      this.show(n, this.run(n, links, doppler), 'main');
      return;
    }
    const fit = Math.floor(Math.sqrt((FRAME_MS * 1e6) / (links * ns)));
    const r = Math.max(MIN_RES, Math.min(n, fit));
    const ms = this.run(r, links, doppler);
    if (dragging) {
      this.worker.cancel();
      this.show(r, ms, 'drag');
    } else {
      this.jobLinks = links;
      this.worker.post({ scenario: app.scenario_json(), n, window: Array.from(this.ctx.view.area), doppler });
      this.show(r, ms, 'preview');
    }
  }

  /** True while a full-resolution map is being computed in the worker. */
  busy() {
    return this.worker.pending;
  }

  /**
   * Computes an n × n map on this thread into the state (with `doppler`, doppler.js job()'s
   * settings: the position and velocity bounds with Doppler); returns the kernel time, ms.
   */
  run(n, links, doppler = null) {
    const { app, st } = this.ctx;
    this.resize(n, !!doppler);
    const [x0, x1, y0, y1] = this.ctx.view.area;
    const grid = { window: [x0, x1, y0, y1], nx: n, ny: n };
    const ms = doppler
      ? app.compute_doppler_maps_in(JSON.stringify({ ...grid, ...doppler }), st.values, st.velValues)
      : app.compute_map_in(JSON.stringify(grid), st.values);
    st.mapWindow = [x0, x1, y0, y1];
    st.mapKernel = doppler ? 'doppler' : 'delay';
    this.learn(n, links, ms, st.mapKernel);
    this.paint();
    return ms;
  }

  /** The state's buffers for an n × n map (and the velocity map's, `doppler`). */
  resize(n, doppler = false) {
    const { st } = this.ctx;
    if (!st.values || st.res !== n) {
      st.values = new Float64Array(n * n);
      st.image = new ImageData(n, n);
      st.mapCanvas.width = n;
      st.mapCanvas.height = n;
      st.res = n;
    }
    if (!doppler) st.velValues = null;
    else if (!st.velValues || st.velValues.length !== n * n) st.velValues = new Float64Array(n * n);
  }

  /** Colours st.values into the map image (on the locked colour range, if any). */
  paint() {
    const { st } = this.ctx;
    const r = this.lock.render(st.values, st.image.data);
    st.range = r.range;
    st.clamped = r.clamped;
    st.mapCanvas.getContext('2d').putImageData(st.image, 0, 0);
    if (this.ctx.doppler) this.ctx.doppler.paint();
  }

  /**
   * What the snapshot view's inset keeps clear of ([x, y, weight] m): every node (never
   * covered); the target is always avoided by drawInset.
   */
  avoidPoints() {
    const n = this.ctx.st.nodes;
    return [...n.transmitters, ...n.receivers].map((p) => [p.x, p.y, HARD]);
  }

  /** The hooks of the pictures (hooks.js: window.pictures). */
  hooks() {
    const { st, view } = this.ctx;
    return {
      getColourRange: () => this.lock.get(),
      setColourRange: (obj) => this.lock.set(obj),
      colourBar: () => (view.drawn.colourBar ? JSON.parse(JSON.stringify(view.drawn.colourBar)) : null),
      inset: () => st.insetControls.state(),
      baselines: () => (view.drawn.baselines || []).map((b) => ({ ...b })),
      range: () => ({ range: st.range ? st.range.slice() : null, clamped: st.clamped.slice() }),
    };
  }

  /**
   * Updates the kernel cost per cell·link from a map that took `ms` (timer resolution floored):
   * the first map of a new link count replaces the estimate (a few links cost more per link
   * than many), later ones are averaged in.
   */
  learn(n, links, ms, kernel) {
    const v = (Math.max(ms, 0.05) * 1e6) / (n * n * Math.max(1, links));
    const c = this.costs[kernel];
    const fresh = !c || links !== c.links;
    this.costs[kernel] = { ns: fresh ? v : 0.5 * c.ns + 0.5 * v, links };
  }

  /** The worker's full-resolution map (only the newest job's is shown). */
  receive(m) {
    if (m.gen !== this.worker.gen) return;
    const { st } = this.ctx;
    const doppler = !!m.velocity;
    this.resize(m.n, doppler);
    st.values = m.values;
    st.velValues = doppler ? m.velocity : null;
    st.mapWindow = m.window;
    st.mapKernel = doppler ? 'doppler' : 'delay';
    this.learn(m.n, this.jobLinks, m.kernelMs, st.mapKernel);
    this.paint();
    this.show(m.n, m.kernelMs, 'worker');
    this.ctx.changed({ draw: true });
  }

  /**
   * #map-ms: the resolution shown (data-res), the full one (data-full), the kernel time (data-ms)
   * and where it ran (data-source: main, drag, preview, worker).
   */
  show(res, ms, source) {
    const el = $('map-ms');
    const n = this.fullRes();
    Object.assign(el.dataset, { ms: String(ms), res: `${res}x${res}`, full: `${n}x${n}`, source });
    const t = `${fixed(ms, 1)} ms`;
    el.textContent = {
      main: `map ${res}×${res}: ${t}`,
      drag: `map ${res}×${res} while dragging (${n}×${n} on release): ${t}`,
      preview: `map ${res}×${res}: ${t} · ${n}×${n} computing in a worker…`,
      worker: `map ${res}×${res}: ${t} (worker)`,
    }[source];
  }

  /**
   * The pinned probe (st.probe {x, y} m: a Shift+click on the map or the URL option
   * `probe=x,y`): its bound into #probe's data-x, data-y, data-rmse-m (the position bound shown,
   * m; 'Infinity' where unbounded) and text; no probe pinned, #probe and its remove button are
   * hidden. With Doppler shown (doppler.js), the bound of the main map: the position bound with
   * delays and range rates (data-rmse-m), the velocity bound (data-velocity-mps, m/s) and the
   * same CPI's delays alone (data-delay-only-m), the core's App.doppler_at (as `scatterloc crlb
   * --doppler`); data-doppler says which ('on' / 'off'; off, the two Doppler attributes are '').
   */
  probe() {
    const { app, wasm, st } = this.ctx;
    const el = $('probe');
    const pin = st.probe;
    el.hidden = !pin;
    $('probe-clear').hidden = !pin;
    if (!pin) {
      Object.assign(el.dataset, { rmseM: '', velocityMps: '', delayOnlyM: '', doppler: 'off' });
      el.textContent = 'probe –';
      return;
    }
    const at = `probe (${fixed(pin.x, 2)}, ${fixed(pin.y, 2)}) m`;
    const job = this.dopplerJob();
    if (job) {
      const d = app.doppler_at(pin.x, pin.y, JSON.stringify(job));
      const num = (v) => String(v === null ? Infinity : v); // null: unbounded
      Object.assign(el.dataset, {
        x: String(pin.x), y: String(pin.y), rmseM: num(d.position_rmse_m),
        velocityMps: num(d.velocity_rmse_mps), delayOnlyM: num(d.delay_only_position_rmse_m), doppler: 'on',
      });
      el.textContent = `${at}: ${d.position_label}, v ${d.velocity_label} with Doppler (delays only ${d.delay_only_label})`;
      return;
    }
    const rmse = app.rmse_at(pin.x, pin.y);
    Object.assign(el.dataset, { x: String(pin.x), y: String(pin.y), rmseM: String(rmse), velocityMps: '', delayOnlyM: '', doppler: 'off' });
    el.textContent = `${at}: ${wasm.format_length(rmse, 4)}`;
  }

  /** Pins the probe at (x, y) m (null: removes it). */
  pinProbe(x, y) {
    this.ctx.st.probe = x === null ? null : { x, y };
    this.probe();
  }

  /** Places the target at (x, y) m with the next noise seed. */
  placeTarget(x, y) {
    const { st } = this.ctx;
    st.target = { x, y, seed: st.nextSeed++ };
    this.ctx.changed({ target: true });
  }

  /** A new noise realisation for the placed target. */
  resample() {
    const { st } = this.ctx;
    if (st.target) st.target.seed = st.nextSeed++;
    this.ctx.changed({ target: true });
  }

  clearTarget() {
    this.ctx.st.target = null;
    this.ctx.changed({ target: true });
  }

  /** Re-simulates the placed target's snapshot (st.snap; null without a target). */
  simulateTarget() {
    const { app, st } = this.ctx;
    st.snap = st.target ? app.simulate_fix(st.target.x, st.target.y, st.target.seed) : null;
    return st.snap;
  }

  /** Redraws the canvas (see drawScene). */
  draw() {
    drawScene(this.ctx.view, this.ctx.st, this.ctx.wasm);
    if (this.ctx.doppler) this.ctx.doppler.draw();
  }
}

/** An image flipped to y-up into the box (x, y, w, h) CSS px (its row 0 at the bottom). */
function drawFlipped(ctx, image, x, y, w, h, quality) {
  ctx.save();
  ctx.imageSmoothingEnabled = true;
  if (quality) ctx.imageSmoothingQuality = quality;
  ctx.translate(x, y + h);
  ctx.scale(1, -1);
  ctx.drawImage(image, 0, 0, w, h);
  ctx.restore();
}

/**
 * The heatmap: the wasm-coloured RGBA image (row 0 = lowest y), flipped to y-up, over the window
 * it was computed for (st.mapWindow): until a new window's map arrives, the last one is drawn
 * where it lies in the new window.
 */
export function drawMap(ctx, view, st) {
  if (!st.mapCanvas || !st.mapWindow) return;
  const [x0, x1, y0, y1] = st.mapWindow;
  const a = view.toPixel(x0, y1);
  const b = view.toPixel(x1, y0);
  clipTo(ctx, view.rect);
  drawFlipped(ctx, st.mapCanvas, a.x, a.y, b.x - a.x, b.y - a.y, 'high');
  ctx.restore();
}

export function drawColorbar(ctx, view, st, w, suffix = '') {
  const r = view.rect;
  const bx = r.x + r.w + 18;
  const bw = 14;
  drawFlipped(ctx, st.barCanvas, bx, r.y, bw, r.h);
  ctx.strokeStyle = C.frame;
  ctx.lineWidth = 1;
  ctx.strokeRect(bx + 0.5, r.y + 0.5, bw, r.h);
  ctx.font = FONT;
  ctx.fillStyle = C.text;
  ctx.textAlign = 'left';
  ctx.textBaseline = 'middle';
  const [min, max] = st.range || [Infinity, Infinity];
  // A locked range that cells pass: "≤ min" / "≥ max" at that end (colour-lock.js), its tick
  // labels within 14 px of the end left out.
  const lockedScale = st.colourLock ? st.colourLock.scale() : null;
  const clamped = st.clamped || [0, 0];
  const ends = [
    { on: !!lockedScale && clamped[0] > 0, y: r.y + r.h, text: `≤ ${w.format_length(min, 3)}${suffix}`, base: 'bottom' },
    { on: !!lockedScale && clamped[1] > 0, y: r.y, text: `≥ ${w.format_length(max, 3)}${suffix}`, base: 'top' },
  ];
  const drawnTicks = [];
  // The figures' algorithm (core colorbar_ticks): labels thinned to the bar's height, minor
  // ticks (empty label) drawn shorter.
  const maxLabels = Math.max(2, Math.floor(r.h / 24));
  for (const t of w.colorbar_ticks(min, max, maxLabels)) {
    const y = r.y + r.h - t.frac * r.h;
    const len = t.label ? 5 : 3;
    ctx.beginPath(); ctx.moveTo(bx + bw, y); ctx.lineTo(bx + bw + len, y); ctx.stroke();
    const label = t.label && !ends.some((e) => e.on && Math.abs(e.y - y) < 14);
    // `suffix`: '/s' on a velocity map's lengths (the figures' ChartOptions.value_suffix).
    if (label) ctx.fillText(`${t.label}${suffix}`, bx + bw + 8, y);
    drawnTicks.push({ value_m: t.value_m, frac: t.frac, label: label ? `${t.label}${suffix}` : '' });
  }
  for (const e of ends.filter((x) => x.on)) {
    ctx.textBaseline = e.base;
    ctx.fillText(e.text, bx + bw + 8, e.y);
  }
  ctx.textBaseline = 'middle';
  view.drawn.colourBar = {
    min_m: min, max_m: max, locked: !!lockedScale, ticks: drawnTicks,
    marks: ends.filter((x) => x.on).map((x) => x.text), bar: { x: bx, y: r.y, w: bw, h: r.h },
  };
  // Unbounded swatch under the bar.
  ctx.fillStyle = st.unboundedColor;
  ctx.fillRect(bx, r.y + r.h + 10, bw, 10);
  ctx.strokeRect(bx + 0.5, r.y + r.h + 10.5, bw, 10);
  ctx.fillStyle = C.muted;
  // Where the canvas is too narrow for the word (a phone), the symbol.
  const room = view.width - (bx + bw + 8);
  ctx.fillText(ctx.measureText('unbounded').width <= room ? 'unbounded' : '∞', bx + bw + 8, r.y + r.h + 15);
}

/** Tx–Rx baselines (dashed), then the node markers (`n` = App.nodes()). */
export function drawNetwork(ctx, view, n, selected) {
  ctx.setLineDash([4, 4]);
  ctx.strokeStyle = C.baseline;
  ctx.lineWidth = 1;
  ctx.beginPath();
  // Clipped to the plot (view.clipSegment), so none crosses the colour bar or the margins.
  const drawn = [];
  for (const [k, l] of n.links) {
    const a = view.toPixel(n.transmitters[k].x, n.transmitters[k].y);
    const b = view.toPixel(n.receivers[l].x, n.receivers[l].y);
    const c = view.clipSegment(a, b);
    if (!c) continue;
    ctx.moveTo(c[0].x, c[0].y); ctx.lineTo(c[1].x, c[1].y);
    drawn.push({ tx: k, rx: l, a: c[0], b: c[1] });
  }
  ctx.stroke();
  view.drawn.baselines = drawn;
  ctx.setLineDash([]);
  drawNodes(ctx, view, n.receivers, n.transmitters, selected);
}

/**
 * Each link's curve `key` ('outline': closed, 'arc': open) in its plot colour at `alpha`, over a
 * `casing` line `casingPx` px wider (a CSS colour; none when null or transparent).
 */
function linkCurves(ctx, tr, links, key, alpha, casing = null, casingPx = 2) {
  const closed = key === 'outline';
  const cased = casing && casing !== 'transparent';
  const width = ctx.lineWidth;
  links.forEach((l, i) => {
    if (l[key].length < (closed ? 3 : 2)) return;
    polyline(ctx, tr, l[key], closed);
    if (cased) {
      ctx.globalAlpha = 1;
      ctx.strokeStyle = casing; ctx.lineWidth = width + casingPx;
      ctx.stroke();
      ctx.lineWidth = width;
    }
    ctx.strokeStyle = linkColor(i);
    ctx.globalAlpha = alpha;
    ctx.stroke();
  });
  ctx.globalAlpha = 1;
}

/** Iso-delay ellipses and markers of the simulated snapshot in the main view. */
function drawTargetMain(ctx, view, fix) {
  clipTo(ctx, view.rect);
  ctx.lineWidth = 1.25;
  linkCurves(ctx, view, fix.links, 'outline', 0.9, C.mapCasing, 3.5);
  ctx.restore();
  const t = view.toPixel(fix.truth.x, fix.truth.y);
  cross(ctx, t, 6, '#0d1017', 4);
  cross(ctx, t, 6, '#ffffff', 2);
  if (fix.fix) {
    const f = view.toPixel(fix.fix.x, fix.fix.y);
    ctx.beginPath(); ctx.arc(f.x, f.y, 9, 0, FULL);
    ctx.strokeStyle = C.fix; ctx.lineWidth = 1.5; ctx.stroke();
  }
}

/**
 * Zoom inset around the target: iso-delay ellipses, CRLB and LM (or EKF) 1σ ellipses, scale bar.
 * `title` names it; inside the plot it keeps off the `avoid` points ([[x, y, weight?], …] m) if it can.
 */
function drawInset(ctx, view, fix, w, title, avoid, controls) {
  const t = view.toPixel(fix.truth.x, fix.truth.y);
  const placed = placeInset(view, t, avoid, controls);
  if (!placed) return null;
  const { size, box } = placed;
  const z = new Zoom(box.x, box.y, size, fix.truth, fix.view_radius_m);
  // Leader line from the target to the inset.
  ctx.strokeStyle = 'rgba(255,255,255,0.45)';
  ctx.lineWidth = 1;
  ctx.setLineDash([3, 3]);
  ctx.beginPath(); ctx.moveTo(t.x, t.y);
  ctx.lineTo(box.x + size / 2, box.y + (t.y < box.y ? 0 : size)); ctx.stroke();
  ctx.setLineDash([]);
  ctx.save();
  ctx.shadowColor = 'rgba(0,0,0,0.5)'; ctx.shadowBlur = 12;
  // The inset's colours follow the theme (C.inset*, style.css --inset-*: draw.js applyThemeColors).
  ctx.fillStyle = C.insetBg;
  ctx.fillRect(box.x, box.y, size, size);
  ctx.restore();
  clipTo(ctx, { x: box.x, y: box.y, w: size, h: size });
  ctx.lineWidth = 1.25;
  // The core hands over only the arc near the target, so no path is millions of pixels wide.
  linkCurves(ctx, z, fix.links, 'arc', 0.85, C.insetCasing);
  const c = z.toPixel(fix.truth.x, fix.truth.y);
  if (fix.crlb.ellipse) {
    ctx.setLineDash([5, 4]); ctx.lineWidth = 2; ctx.strokeStyle = C.insetCrlb;
    ellipsePath(ctx, z, fix.crlb.ellipse); ctx.stroke();
    ctx.setLineDash([]);
  }
  if (fix.fix) {
    const f = z.toPixel(fix.fix.x, fix.fix.y);
    if (fix.fix.ellipse) {
      ctx.lineWidth = 2; ctx.strokeStyle = C.insetFix;
      ellipsePath(ctx, z, fix.fix.ellipse); ctx.stroke();
      ctx.fillStyle = C.insetFixFill; ctx.fill();
    }
    ctx.beginPath(); ctx.arc(f.x, f.y, 3.5, 0, FULL); ctx.fillStyle = C.insetFix; ctx.fill();
  }
  cross(ctx, c, 5, C.insetTruth, 2);
  // Scale bar.
  const bar = w.scale_bar(fix.view_radius_m * 0.8);
  if (bar) {
    const len = z.len(bar.length_m);
    const y = box.y + size - 14;
    ctx.strokeStyle = C.insetText; ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(box.x + 12, y - 4); ctx.lineTo(box.x + 12, y); ctx.lineTo(box.x + 12 + len, y); ctx.lineTo(box.x + 12 + len, y - 4);
    ctx.stroke();
    ctx.font = FONT; ctx.fillStyle = C.insetText; ctx.textAlign = 'left'; ctx.textBaseline = 'bottom';
    haloText(ctx, bar.label, box.x + 16 + len, y + 4, C.insetHalo);
  }
  // The title stays left of the × (inset.js): cut with '…' if it is too long, the full text is
  // the header's tooltip and accessible name then.
  ctx.font = FONT_B; ctx.fillStyle = C.insetText; ctx.textAlign = 'left'; ctx.textBaseline = 'top';
  const room = controls ? controls.titleRoom(size) : size - 16;
  const shown = fitText(ctx, title, room);
  haloText(ctx, shown, box.x + 8, box.y + 7, C.insetHalo);
  const m = ctx.measureText(shown);
  const titleBox = { x: box.x + 8 - m.actualBoundingBoxLeft, y: box.y + 7 - m.actualBoundingBoxAscent,
    w: m.actualBoundingBoxLeft + m.actualBoundingBoxRight, h: m.actualBoundingBoxAscent + m.actualBoundingBoxDescent };
  ctx.restore();
  ctx.strokeStyle = C.frame; ctx.lineWidth = 1;
  ctx.strokeRect(box.x + 0.5, box.y + 0.5, size, size);
  return { x: box.x, y: box.y, size, colors: { bg: C.insetBg, title: C.insetText, halo: C.insetHalo },
    title: { text: shown, full: title, box: titleBox } };
}

/**
 * Where the inset goes ({size, box: {x, y}} CSS px, or null: closed, or no room): where the user
 * moved it (inset.js), else outside the plot when a wide area leaves room above or below it, else
 * the free place in the plot (chooseBox: clear of the target and the `avoid` points, [x, y,
 * weight = 1] m).
 */
function placeInset(view, t, avoid, controls) {
  const r = view.rect;
  const pad = 10;
  const below = view.height - (r.y + r.h) - 52;
  const above = r.y - 4;
  const auto = () => {
    if (below >= 170) {
      const size = Math.min(270, below - pad);
      return { x: r.x + r.w - size, y: r.y + r.h + 52, size };
    }
    if (above >= 170) {
      const size = Math.min(270, above - pad);
      return { x: r.x + r.w - size, y: r.y - size - pad, size };
    }
    const size = Math.min(250, r.w * 0.42, r.h * 0.55);
    if (size < 80) return null;
    const points = avoid.map(([x, y, wt = 1]) => ({ ...view.toPixel(x, y), w: wt, m: wt >= HARD ? 14 : 6 }));
    points.push({ ...t, w: 1e3 * HARD, m: 12 });
    return chooseBox(r, Math.floor(size), points, pad);
  };
  const preferred = below >= 170 ? Math.min(270, below - pad) : above >= 170 ? Math.min(270, above - pad)
    : Math.min(250, r.w * 0.42, r.h * 0.55);
  const b = controls ? controls.place(Math.max(80, Math.floor(preferred)), auto) : auto();
  if (!b) return null;
  return { size: b.size, box: { x: b.x, y: b.y } };
}

/**
 * Redraws the whole canvas from the state: `st.fix` is a snapshot (or a snapshot-shaped track
 * frame), `st.overlay(ctx, view)` draws extra layers under the markers, `st.insetTitle` names
 * the zoom inset and `st.insetAvoid` lists points it should not cover.
 */
function drawScene(view, st, w) {
  const ctx = view.context();
  view.clear(ctx, C.bg);
  drawMap(ctx, view, st);
  drawAxes(ctx, view, w);
  drawColorbar(ctx, view, st, w);
  // Zoomed in (zoom.js), the layers stay inside the plot; at the whole area the node labels may
  // reach into the margin.
  const zoomed = view.zoomed();
  if (zoomed) clipTo(ctx, view.rect);
  if (st.overlay) st.overlay(ctx, view);
  if (st.fix) drawTargetMain(ctx, view, st.fix);
  if (st.areaOutline) drawAreaOutline(ctx, view, st.areaOutline);
  drawNetwork(ctx, view, st.nodes, st.selected);
  if (zoomed) ctx.restore();
  drawScaleBar(ctx, view, w);
  let inset = null;
  const t = st.fix ? view.toPixel(st.fix.truth.x, st.fix.truth.y) : null;
  const targetShown = !!t && view.inPlot(t.x, t.y);
  if (targetShown) inset = drawInset(ctx, view, st.fix, w, st.insetTitle || 'target zoom', st.insetAvoid || [], st.insetControls);
  if (st.insetControls) st.insetControls.shown(inset, targetShown);
}

/**
 * The scenario's area [x0, x1, y0, y1] m as a dashed outline (shown when the view is widened to
 * show a node outside it, outside.js), clipped to the plot.
 */
function drawAreaOutline(ctx, view, a) {
  const p = view.toPixel(a[0], a[3]);
  const q = view.toPixel(a[1], a[2]);
  clipTo(ctx, view.rect);
  ctx.setLineDash([6, 4]);
  ctx.strokeStyle = C.text;
  ctx.lineWidth = 1.5;
  ctx.strokeRect(p.x, p.y, q.x - p.x, q.y - p.y);
  ctx.setLineDash([]);
  ctx.restore();
}

/** A 1-pixel-wide canvas holding the colour bar gradient (dark first = bottom). */
function makeBarCanvas(rgba) {
  const n = rgba.length / 4;
  const c = document.createElement('canvas');
  c.width = 1;
  c.height = n;
  const img = new ImageData(new Uint8ClampedArray(rgba), 1, n);
  c.getContext('2d').putImageData(img, 0, 0);
  return c;
}

/**
 * Registers the page state's `grid` (the map's resolution) and `target` (the placed target and
 * the next target's seed) sections, in that order.
 * @param {object} ctx - app.js ctx: {wasm, st, changed}
 */
export function registerMapState(ctx) {
  const { wasm, st } = ctx;
  registerSection('grid', {
    get: () => ({ res: Number($('resolution').value) }),
    check: (v) => {
      fields(v, 'state.grid', ['res']);
      choice(v.res, 'state.grid.res', 'resolution');
    },
    apply: (v) => {
      $('resolution').value = String(v.res);
      ctx.changed({ map: true });
    },
  });

  registerSection('target', {
    get: () => ({ point: st.target ? { ...st.target } : null, next_seed: st.nextSeed }),
    check: (v) => {
      fields(v, 'state.target', ['point', 'next_seed']);
      number(v.next_seed, 'state.target.next_seed', SEED_RANGE);
      if (v.point === null) return;
      fields(v.point, 'state.target.point', ['x', 'y', 'seed']);
      number(v.point.x, 'state.target.point.x');
      number(v.point.y, 'state.target.point.y');
      wasm.check_point('state.target.point', v.point.x, v.point.y);
      number(v.point.seed, 'state.target.point.seed', SEED_RANGE);
    },
    apply: (v) => {
      st.target = v.point ? { ...v.point } : null;
      st.nextSeed = v.next_seed;
      ctx.changed({ target: true });
    },
  });
}
