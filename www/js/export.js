// "Save figure": writes the current view as a file. PNG is the canvas as it is (canvas.toBlob);
// SVG is drawn by the wasm core with the CLI's plotters chart code (App.map_svg, Track.map_svg,
// tracking_chart_svg, mtl_scene_svg): the map, the nodes, the target's snapshot or the track, and
// the colour bar; the multi-target scene with its ranges, detections and targets. Each SVG shows
// the window on screen (zoom.js). Files are named `<scenario>-<view>-<figure>.<ext>`, e.g.
// sensors2019-snapshot-map.svg, sensors2019-tracking-rmse.svg, multi-target-scene.svg. With
// "Several people" on (tracking view, multi.js), the map is the run's map at the scan shown
// (people_map_svg: nodes, true paths, labelled tracks, 1σ ellipses) and the chart its GOSPA chart
// (people_chart_svg, "GOSPA chart"); PNG is the map canvas or #multi-chart as they are; files
// <scenario>-tracking-people-map.<ext>, <scenario>-tracking-people-gospa.<ext>. With Doppler on
// in the snapshot view (doppler.js), "Map" is the position bound with Doppler and "Velocity map"
// the velocity bound, one figure per quantity as `crlb-map --doppler --quantity position|velocity
// --out f.svg` draws them (App.map_svg's `doppler` option; PNG: #plot or #vel-plot as they are);
// files <scenario>-snapshot-doppler-position.<ext>, <scenario>-snapshot-doppler-velocity.<ext>.
// Nothing here runs until the button is pressed (the drag stays as fast as it was).

import { $, errorText, showError } from './dom.js';
import { DataExport } from './data-export.js';

/** Width of an exported SVG figure, px (the CLI's default); the height fits the plot. */
const SVG_WIDTH = 1000;
/** Height of the exported RMSE chart, px (the CLI's tracking figure: 1000 × 620). */
const CHART_HEIGHT = 620;

/** `name` as a file-name part: lower case, runs of other characters as one dash. */
export function slug(name) {
  const s = String(name).toLowerCase().replace(/[^a-z0-9._]+/g, '-').replace(/^-+|-+$/g, '');
  return s || 'scenario';
}

export class FigureExport {
  /** @param {object} ctx - {app, wasm, st, view, tracking, mtl} (app.js). */
  constructor(ctx) {
    this.ctx = ctx;
    this.dryRun = false; // true: build the download link but do not click it (tests)
    this.last = null; // {name, type, size, ms, blob, href, mode, what, format}
    this.count = 0;
    $('figure-save').addEventListener('click', () => this.save());
    this.data = new DataExport(ctx); // "Export data" (data-export.js)
    this.mode = null;
    // "Several people" on or off changes the chart choice's label and the data choices.
    $('multi-walkers').addEventListener('change', () => this.relabel());
  }

  /** The "Several people" run when it is on in the tracking view, else null. */
  people() {
    const { st, tracking } = this.ctx;
    const multi = tracking && tracking.multi;
    return st.mode === 'tracking' && multi && multi.on ? multi : null;
  }

  /**
   * The Doppler settings of the snapshot view's maps (doppler.js job(): {cpi, velocity_mps}) when
   * they are shown, else null.
   */
  dopplerJob() {
    const { st, doppler } = this.ctx;
    return st.mode === 'snapshot' && doppler ? doppler.job() : null;
  }

  /**
   * The chart choice's label ("GOSPA chart" with several people), the velocity map's choice
   * (only with Doppler shown; doppler.js sync() calls this) and the data choices.
   */
  relabel() {
    const what = $('figure-what');
    const rmse = what.querySelector('option[value="rmse"]');
    rmse.textContent = this.people() ? 'GOSPA chart' : 'RMSE chart';
    const vel = what.querySelector('option[value="velocity"]');
    vel.hidden = !this.dopplerJob();
    vel.disabled = vel.hidden;
    if (vel.disabled && what.value === 'velocity') what.value = 'map';
    this.data.refresh();
  }

  /** Shows the choices of `mode`: the RMSE chart only in tracking. */
  setMode(mode) {
    const what = $('figure-what');
    const rmse = what.querySelector('option[value="rmse"]');
    rmse.hidden = mode !== 'tracking';
    rmse.disabled = mode !== 'tracking';
    if (rmse.disabled && what.value === 'rmse') what.value = 'map';
    what.querySelector('option[value="map"]').textContent = mode === 'mtl' ? 'Scene' : 'Map';
    this.data.setMode(mode);
    this.relabel();
  }

  /** The file name of figure `what` ('map' | 'rmse' | 'velocity') of the current view. */
  fileName(what, ext) {
    const { app, st } = this.ctx;
    if (st.mode === 'mtl') return `multi-target-scene.${ext}`;
    if (this.dopplerJob()) return `${slug(app.scenario().name)}-snapshot-doppler-${what === 'velocity' ? 'velocity' : 'position'}.${ext}`;
    if (this.people()) return `${slug(app.scenario().name)}-tracking-people-${what === 'rmse' ? 'gospa' : 'map'}.${ext}`;
    return `${slug(app.scenario().name)}-${st.mode}-${what}.${ext}`;
  }

  /** Saves the figure chosen in #figure-what as #figure-format; errors go to the banner. */
  async save() {
    const { st } = this.ctx;
    this.relabel();
    const chosen = $('figure-what').value;
    const doppler = !!this.dopplerJob();
    const what = st.mode === 'tracking' || (doppler && chosen === 'velocity') ? chosen : 'map';
    const format = $('figure-format').value;
    const t0 = performance.now();
    try {
      // The RMSE chart of a study still running is labelled partial (chartText), here and on the canvas.
      const partial = what === 'rmse' && !this.people() ? this.ctx.tracking.mc.chartText().partial : '';
      const blob = format === 'svg' ? this.svg(what) : await this.png(what);
      this.download(blob, this.fileName(what, format), {
        mode: st.mode, what, format, ms: performance.now() - t0, partial, people: !!this.people(), doppler,
      });
    } catch (e) {
      showError(`Save figure: ${errorText(e)}`);
      console.error(e);
    }
  }

  /** The SVG text of figure `what` from the core, as a Blob. */
  svg(what) {
    const { app, wasm, st, view, tracking, mtl } = this.ctx;
    if (st.mode === 'mtl') {
      const text = wasm.mtl_scene_svg(JSON.stringify(mtl.scene), SVG_WIDTH, 0, JSON.stringify({ window: Array.from(mtl.view.area) }));
      return new Blob([text], { type: 'image/svg+xml' });
    }
    const people = this.people();
    if (people) return new Blob([this.peopleSvg(people, what)], { type: 'image/svg+xml' });
    const res = Number($('resolution').value) || 256;
    const options = { window: Array.from(view.area), res };
    // A locked colour range (colour-lock.js) colours the figure as the canvas.
    const locked = st.colourLock ? st.colourLock.scale() : null;
    if (locked) options.scale = locked;
    let text;
    if (what === 'rmse') {
      const mc = tracking.mc;
      const t = mc.chartText();
      text = wasm.tracking_chart_svg(mc.result || '', t.title, t.subtitle, t.caption, SVG_WIDTH, CHART_HEIGHT);
    } else if (st.mode === 'tracking') {
      if (!tracking.track) throw new Error('no track to draw yet');
      const magnify = Number($('track-ex').value) || 1;
      text = tracking.track.map_svg(SVG_WIDTH, 0, tracking.step, magnify, JSON.stringify(options));
    } else {
      // With Doppler: the map of `what` with the settings of the maps shown (the velocity map
      // as its canvas: no target, its own colour range).
      const job = this.dopplerJob();
      const velocity = !!job && what === 'velocity';
      if (job) options.doppler = { ...job, quantity: velocity ? 'velocity' : 'position' };
      if (velocity) delete options.scale;
      if (st.target && !velocity) options.target = { x: st.target.x, y: st.target.y, seed: st.target.seed };
      text = app.map_svg(SVG_WIDTH, 0, JSON.stringify(options));
    }
    return new Blob([text], { type: 'image/svg+xml' });
  }

  /** The SVG text of the several-people figure `what` ('map' | 'rmse': the GOSPA chart). */
  peopleSvg(multi, what) {
    const { wasm, view, tracking } = this.ctx;
    if (!multi.text || !multi.params) throw new Error('no multi-target run yet');
    if (what === 'rmse') {
      const c = $('multi-chart').dataset; // the canvas chart's title and subtitle (multi.js)
      return wasm.people_chart_svg(multi.text, c.title || 'GOSPA per scan', c.subtitle || '', SVG_WIDTH, CHART_HEIGHT);
    }
    const magnify = Number($('track-ex').value) || 1;
    return wasm.people_map_svg(multi.params.scenario, multi.text, SVG_WIDTH, 0, tracking.step, magnify,
      JSON.stringify({ window: Array.from(view.area) }));
  }

  /** The canvas of figure `what` as it is, as a PNG Blob. */
  png(what) {
    const people = this.people();
    if (people && !people.text) return Promise.reject(new Error('no multi-target run yet'));
    const chart = people ? $('multi-chart') : $('track-chart');
    const canvas = what === 'rmse' ? chart : what === 'velocity' ? $('vel-plot') : $('plot');
    return new Promise((resolve, reject) => {
      canvas.toBlob((b) => (b ? resolve(b) : reject(new Error('the canvas gave no image'))), 'image/png');
    });
  }

  /** A download link for `blob` named `name`, clicked (unless dryRun); remembered in `last`. */
  download(blob, name, info) {
    const href = URL.createObjectURL(blob);
    const a = document.createElement('a');
    a.href = href;
    a.download = name;
    a.hidden = true;
    document.body.appendChild(a);
    if (!this.dryRun) a.click();
    a.remove();
    if (this.last) URL.revokeObjectURL(this.last.href);
    this.count += 1;
    this.last = { name, type: blob.type, size: blob.size, blob, href, ...info };
    const btn = $('figure-save');
    Object.assign(btn.dataset, { saved: name, count: String(this.count) });
  }

  /** For the hooks: `last` without the Blob, or null. */
  lastInfo() {
    if (!this.last) return null;
    const { blob, ...rest } = this.last;
    return rest;
  }
}
