// "Export data": the numbers behind the pictures as CSV or JSON files. The map (snapshot and
// tracking views): the CRLB map on screen, its grid and values, written by the core
// (map_data_text); the track (tracking view): time, truth, the filter's estimate and covariance,
// written by the core (Track.data_text); the Monte Carlo curves (tracking view): t, the RMSE of
// each filter, the PCRLB bound, the runs counted and failed, from the core's result JSON. With
// "Several people" on (multi.js), "track" is the run's people (people_data_text: CSV, a row per
// true person and per reported target per scan; JSON, the truth, track and score) in
// `<scenario>-tracking-people.<ext>`, and the Monte Carlo curves (not shown then) are off. Every
// number is the core's, written so that it reads back as the same double. Files are named
// `<scenario>-<view>-<what>.<ext>`.

import { $, errorText, showError } from './dom.js';

/** `name` as a file-name part (export.js's rule). */
function slug(name) {
  const s = String(name).toLowerCase().replace(/[^a-z0-9._]+/g, '-').replace(/^-+|-+$/g, '');
  return s || 'scenario';
}

/** A CSV field of a number: its shortest round-trip text; empty for null / non-finite. */
const csvNum = (v) => (typeof v === 'number' && Number.isFinite(v) ? String(v) : '');

export class DataExport {
  /** @param {object} ctx - {app, wasm, st, view, tracking} (app.js). */
  constructor(ctx) {
    this.ctx = ctx;
    this.dryRun = false;
    this.last = null; // {name, type, size, text, mode, what, format, people}
    this.mode = null;
    $('data-save').addEventListener('click', () => this.save());
  }

  /** The "Several people" run when it is on in the tracking view, else null. */
  people() {
    const { st, tracking } = this.ctx;
    const multi = tracking && tracking.multi;
    return st.mode === 'tracking' && multi && multi.on ? multi : null;
  }

  /**
   * The Doppler settings of the snapshot view's maps (doppler.js job(): {cpi, velocity_mps})
   * when they are shown, else null.
   */
  dopplerJob() {
    const { st, doppler } = this.ctx;
    return st.mode === 'snapshot' && doppler ? doppler.job() : null;
  }

  /**
   * With several people: "track" is their data, the Monte Carlo curves are off. With Doppler
   * shown: "Velocity map data" (the velocity bound beside the map).
   */
  refresh() {
    const what = $('data-what');
    const vel = what.querySelector('option[value="velocity"]');
    vel.hidden = !this.dopplerJob();
    vel.disabled = vel.hidden;
    if (vel.disabled && what.value === 'velocity') what.value = 'map';
    const people = !!this.people();
    const mc = what.querySelector('option[value="mc"]');
    mc.hidden = this.mode !== 'tracking' || people;
    mc.disabled = mc.hidden;
    if (mc.disabled && what.value === 'mc') what.value = this.mode === 'tracking' ? 'track' : 'map';
    what.querySelector('option[value="track"]').textContent = people ? 'People (tracks and truth)' : 'Track';
  }

  /** Shows the choices of `mode`: the track and the Monte Carlo curves only in tracking. */
  setMode(mode) {
    const what = $('data-what');
    for (const v of ['track', 'mc']) {
      const o = what.querySelector(`option[value="${v}"]`);
      o.hidden = mode !== 'tracking';
      o.disabled = mode !== 'tracking';
      if (o.disabled && what.value === v) what.value = 'map';
    }
    $('data-export').hidden = mode === 'mtl';
    this.mode = mode;
    this.refresh();
  }

  /** The text of data `what` ('map' | 'track' | 'mc') as `format` ('csv' | 'json'). */
  text(what, format) {
    const { app, wasm, st, tracking } = this.ctx;
    if (what === 'map' || what === 'velocity') {
      // With Doppler, the values are labelled as the bounds with Doppler they are (their CPI,
      // velocity and floor); the velocity map's column is rmse_mps.
      const job = this.dopplerJob();
      const values = what === 'velocity' ? st.velValues : st.values;
      if (!values || !st.mapWindow || (what === 'velocity' && !job)) throw new Error('no map computed yet');
      // The values must be the kernel's the labels name (map.js st.mapKernel).
      if (!!job !== (st.mapKernel === 'doppler')) throw new Error('the map is still being computed');
      const settings = { window: st.mapWindow, nx: st.res, ny: st.res, scenario: app.scenario().name, format };
      if (job) settings.doppler = { ...job, quantity: what === 'velocity' ? 'velocity' : 'position' };
      return wasm.map_data_text(values, JSON.stringify(settings));
    }
    const people = this.people();
    if (people && what === 'track') {
      if (!people.text) throw new Error('no multi-target run yet');
      return wasm.people_data_text(people.text, format);
    }
    if (people && what === 'mc') throw new Error('no Monte Carlo curves with several people on');
    if (what === 'track') {
      if (!tracking.track) throw new Error('no track simulated yet');
      return tracking.track.data_text(format);
    }
    if (what === 'mc') {
      const mc = tracking.mc;
      if (!mc.result) throw new Error('no Monte Carlo result yet');
      return mcText(JSON.parse(mc.result), app.scenario().name, format);
    }
    throw new Error(`unknown data "${what}"`);
  }

  /** Saves the data chosen in #data-what as #data-format; errors go to the banner. */
  save() {
    const { app, st } = this.ctx;
    const what = $('data-what').value;
    const format = $('data-format').value;
    try {
      const people = !!this.people() && what === 'track';
      const text = this.text(what, format);
      const type = format === 'csv' ? 'text/csv' : 'application/json';
      const kind = this.dopplerJob() && (what === 'map' || what === 'velocity') ? `doppler-${what === 'map' ? 'position' : 'velocity'}` : what;
      const name = `${slug(app.scenario().name)}-${st.mode}-${people ? 'people' : kind}.${format}`;
      const blob = new Blob([text], { type });
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = name;
      a.hidden = true;
      document.body.appendChild(a);
      if (!this.dryRun) a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
      this.last = { name, type, size: blob.size, text, mode: st.mode, what, format, people };
      $('data-save').dataset.saved = name;
    } catch (e) {
      showError(`Export data: ${errorText(e)}`);
    }
  }

  /** For the hooks. */
  hooks() {
    return {
      text: (what, format) => this.text(what, format),
      save: () => this.save(),
      last: () => (this.last ? { ...this.last } : null),
      setDryRun: (on) => { this.dryRun = !!on; },
    };
  }
}

/**
 * The Monte Carlo curves of the core's result `r` (the study's JSON) as CSV (columns `t_s`, then
 * per filter `rmse_<filter>_m`, `runs_<filter>`, `failed_runs_<filter>`, then `rmse_pcrlb_m`
 * (empty where singular) and `study_done` (false: a partial result)) or JSON ({scenario, units, t_s, filters: {name: {rmse_m, runs,
 * failed_runs}}, rmse_pcrlb_m, partial}).
 */
export function mcText(r, scenario, format) {
  const names = Object.keys(r.filters || {});
  const filters = {};
  for (const n of names) {
    const f = r.filters[n];
    filters[n] = { rmse_m: f.rmse_m, runs: f.runs, failed_runs: f.failed_runs };
  }
  if (format === 'json') {
    return JSON.stringify({
      scenario,
      units: 's, m',
      meaning: 'rmse_m: the RMSE over the counted runs of each filter; rmse_pcrlb_m: the posterior CRLB '
        + '(null where the information is singular); failed_runs: runs whose filter failed numerically, left out of its curve',
      partial: !r.done,
      t_s: r.t_s,
      filters,
      rmse_pcrlb_m: r.rmse_pcrlb_m,
    });
  }
  if (format !== 'csv') throw new Error(`format "${format}" is not csv or json`);
  const lines = [['t_s', ...names.flatMap((n) => [`rmse_${n}_m`, `runs_${n}`, `failed_runs_${n}`]), 'rmse_pcrlb_m', 'study_done'].join(',')];
  r.t_s.forEach((t, k) => {
    const per = names.flatMap((n) => [csvNum(filters[n].rmse_m[k]), filters[n].runs, filters[n].failed_runs]);
    lines.push([csvNum(t), ...per, csvNum(r.rmse_pcrlb_m[k]), r.done ? 'true' : 'false'].join(','));
  });
  return `${lines.join('\n')}\n`;
}
