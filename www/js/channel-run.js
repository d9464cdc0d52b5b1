// The channel view's running job (a part of the Channel class, channel.js): Simulate walk, Run
// (the estimation and tracking in a Web Worker through channel-job.js, with progress by phase
// and Stop), receiving the result, the status line and its errors, and marking the result stale
// when its inputs change.

import { $, clip, clearError, errorText, fillKeyValues, fixed } from './dom.js';
import { ChannelStopped } from './channel-job.js';
import { lossName } from './channel-draw.js';
import { checkChannelSettings, parseChannelField } from './channel-settings.js';
import { INPUTS, parseTruth } from './channel-files.js';

/** "Simulate walk": the simulator's walk (the scene's) for 15 s, one snapshot every 50 ms. */
export const SIMULATE_SETTINGS = { duration_s: 15, dt_s: 0.05 };

/** The settings a run depends on (a change after a run says so). */
const RUN_KEYS = ['filter', 'particles', 'seed', 'process_noise', 'p_fa', 'max_paths', 'extent_sigma_m',
  'statics', 'delay_reference', 'background_time_s', 'cpi_snapshots', 'range_rate_floor_mps', 'calibration', 'empty_from_s', 'empty_to_s', 'targets'];
/** The run's settings as the status line names them when they change. */
const RUN_LABELS = {
  filter: 'filter', particles: 'particles', seed: 'seed', process_noise: 'q', p_fa: 'P_fa', max_paths: 'max paths',
  extent_sigma_m: 'extent σ', statics: 'statics', delay_reference: 'delays', background_time_s: 'background τ',
  cpi_snapshots: 'CPI snapshots', range_rate_floor_mps: 'range-rate floor', calibration: 'empty area', empty_from_s: 'empty from', empty_to_s: 'empty to', targets: 'people',
};

/**
 * What changed between two scenario JSON texts, named for the status line: each node moved
 * ("Rx2 moved"), added or removed, and any other change as "scenario changed (radio)" by its
 * top-level key. Empty when the texts are equal.
 */
export function scenarioChanges(before, now) {
  if (before === now) return [];
  let a;
  let b;
  try {
    a = JSON.parse(before);
    b = JSON.parse(now);
  } catch {
    return ['scenario changed'];
  }
  const out = [];
  for (const kind of ['transmitters', 'receivers']) {
    const was = a[kind] || [];
    const is = b[kind] || [];
    for (let i = 0; i < Math.max(was.length, is.length); i++) {
      const [p, q] = [was[i], is[i]];
      if (!p) out.push(`${q.name} added`);
      else if (!q) out.push(`${p.name} removed`);
      else if (p.position_m[0] !== q.position_m[0] || p.position_m[1] !== q.position_m[1]) out.push(`${q.name} moved`);
      else if (JSON.stringify(p) !== JSON.stringify(q)) out.push(`${q.name} changed`);
    }
  }
  const keys = [...new Set([...Object.keys(a), ...Object.keys(b)])]
    .filter((k) => k !== 'transmitters' && k !== 'receivers' && JSON.stringify(a[k]) !== JSON.stringify(b[k]));
  if (keys.length) out.push(`scenario changed (${keys.join(', ')})`);
  return out.length ? out : ['scenario changed'];
}

/**
 * The track's segments as the status line names them, e.g. "2 segments: 0.3–16.4 s (lost:
 * innovation), 17.1–20.0 s" (TRACK.json's `segments`).
 */
export function segmentsText(segments) {
  if (!segments || !segments.length) return 'no segment: the track never started (no fix was confirmed)';
  const parts = segments.map((g) => `${fixed(g.t_first_s, 1)}–${fixed(g.t_last_s, 1)} s${g.end === 'end' ? '' : ` (lost: ${lossName(g.end)})`}`);
  return `${segments.length} segment${segments.length === 1 ? '' : 's'}: ${parts.join(', ')}`;
}

/**
 * Several people as the status line names them (the worker's people document): "3 labelled
 * tracks (#0, #1, #4, PMB)", and with a truth "· mean GOSPA 0.21 m, 0 label switches".
 */
export function peopleText(p) {
  const n = p.track.tracks.length;
  const labels = p.track.tracks.map((t) => `#${t.label}`).join(', ');
  let text = `${n} labelled track${n === 1 ? '' : 's'}${n ? ` (${labels}, ${p.track.method.toUpperCase()})` : ` (${p.track.method.toUpperCase()})`}`;
  if (p.score) {
    const s = p.score;
    text += ` · mean GOSPA ${fixed(s.mean_gospa_m, 2)} m, ${s.switches} label switch${s.switches === 1 ? '' : 'es'}`;
  }
  return text;
}

/**
 * The phases of a run in order: [phase, name in the status line, share of the progress bar].
 * The worker reports estimate (link-snapshots), track, figure (links) and results (its texts
 * being written); the page load (reading them into ChannelFigures) and draw (the charts). The
 * shares are the measured split of a 1528-snapshot, 4-link recording (see docs/page.md; the
 * --dev build: reading and estimates 3.6 s, track 0.2 s, figure 0.3 s, results 1.3 s, reading
 * them 0.5 s, charts 0.8 s).
 */
const RUN_PHASES = [
  ['estimate', 'Estimating the statics and paths', 0.55],
  ['track', 'Tracking', 0.04],
  ['figure', 'Drawing up the delay figure', 0.06],
  ['results', 'Handing the results to the page', 0.18],
  ['load', 'Reading the results', 0.07],
  ['draw', 'Drawing the charts', 0.1],
];

/** The worker's phase times of a result (ms): parse, estimate, track, figure. */
function sumTimings(t) {
  return (t.parse_ms || 0) + (t.estimate_ms || 0) + (t.track_ms || 0) + (t.figure_ms || 0);
}

/** Resolves after the next frame was painted (a status set before it shows). */
function nextPaint() {
  return new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0)));
}

/** The running-job part of the Channel class (channel.js mixes it in). */
export const channelRun = {
  /** Simulate walk, Run and Stop. */
  bindRun() {
    $('chan-simulate').addEventListener('click', () => this.simulate());
    $('chan-run').addEventListener('click', () => this.run());
    $('chan-stop').addEventListener('click', () => this.stop());
    // One person or several (a page setting: the worker's job is told with set_targets).
    $('chan-targets').addEventListener('change', () => {
      this.s = { ...this.s, targets: $('chan-targets').value };
      this.showStale();
    });
  },

  /**
   * The core's ChannelRequest of the panel's text as it stands (an input not yet committed with
   * Enter counts too), checked (this.s updated); throws the named error. Run and Replay use it.
   */
  panelSettings() {
    for (const [key, id, label] of INPUTS) {
      const v = parseChannelField(key, $(id).value, label);
      this.s = checkChannelSettings({ ...this.s, [key]: v });
    }
    return this.jobSettings();
  },

  /** Run, Stop, Simulate and the result's controls enabled as the job and the result allow. */
  showButtons() {
    const replaying = this.replaying();
    const busy = this.running !== null || replaying;
    $('chan-run').disabled = busy || !this.rec;
    $('chan-replay').disabled = busy || !this.rec;
    $('chan-stop').disabled = !busy;
    $('chan-simulate').disabled = busy;
    const has = !!this.result;
    $('chan-save').disabled = !has;
    $('chan-play').disabled = !has;
    $('chan-scrub').disabled = !has;
    $('chan-link').disabled = !has;
  },

  /** The status line (`state`: idle, running, done, error, stopped). */
  status(text, state) {
    const el = $('chan-status');
    el.textContent = text;
    el.dataset.state = state;
  },

  /**
   * What differs now from the inputs of the result shown, each named for the status line
   * ("Rx2 moved", "P_fa changed", "recording walk.npz opened", …); empty when it is current or
   * there is none (any change that invalidates a result marks it stale).
   */
  staleReasons() {
    const r = this.result;
    if (!r) return [];
    const out = [];
    if (this.rec && this.rec !== r.rec) out.push(`recording ${clip(this.rec.name)} opened`);
    out.push(...scenarioChanges(r.scenario, this.ctx.app.scenario_json()));
    for (const k of RUN_KEYS) if (r.settings[k] !== this.s[k]) out.push(`${RUN_LABELS[k] || k} changed`);
    const calNow = this.s.calibration === 'file' && this.cal ? this.cal.bytes : null;
    if (this.s.calibration === 'file' && r.settings.calibration === 'file' && calNow !== r.calibration) {
      out.push(calNow ? `empty recording ${clip(this.cal.name)} opened` : 'empty recording removed');
    }
    const truthNow = this.truth ? this.truth.text : null;
    if (truthNow !== r.truthText) out.push(truthNow ? `truth ${clip(this.truth.name)} opened` : 'truth removed');
    return out;
  },

  /**
   * Marks the result stale when its inputs changed (staleReasons): the status line names the
   * changes ("stale: Rx2 moved · …", state "stale"), the map draws the track faded and dashed
   * and the charts faded, until Run again. Redraws the map when the mark comes or goes (not
   * when called from the map's own drawing: `fromDraw`).
   */
  showStale(fromDraw = false) {
    if (!this.result || this.running) return;
    const reasons = this.staleReasons();
    const was = this.stale.join('\n');
    const same = was === reasons.join('\n');
    this.stale = reasons;
    // From the map's drawing only a change of the reasons rewrites the status line (a file's
    // error stays until then).
    if (fromDraw && same) return;
    $('chan-figures').classList.toggle('stale', reasons.length > 0);
    if (reasons.length) {
      this.status(`stale: ${reasons.join(', ')} (press Run) · ${this.doneText()}`, 'stale');
    } else {
      this.status(this.doneText(), 'done');
    }
    if (!fromDraw && !same) this.redraw();
  },

  /**
   * The job's settings from this.s: the core's ChannelRequest as JSON (its field names; the
   * worker's ChannelJob parses it as such and the core checks it).
   */
  jobSettings() {
    const s = this.s;
    const out = {
      max_paths: s.max_paths, pfa: s.p_fa, filter: s.filter, process_noise: s.process_noise,
      extent_sigma_m: s.extent_sigma_m, statics: s.statics, background_time_s: s.background_time_s,
    };
    // 1 snapshot per scan: no CPI (the request's default, as `cir estimate` without --cpi-snapshots).
    if (s.cpi_snapshots > 1) {
      Object.assign(out, { cpi_snapshots: s.cpi_snapshots, range_rate_floor_mps: s.range_rate_floor_mps });
    }
    if (s.delay_reference !== 'auto') out.delay_reference = s.delay_reference;
    if (s.filter === 'pf') Object.assign(out, { particles: s.particles, seed: s.seed });
    if (s.calibration === 'range') out.calibration_range_s = [s.empty_from_s, s.empty_to_s];
    return out;
  },

  /** Simulates a walk through the scenario (the simulator's files) and opens it. */
  async simulate() {
    this.pause();
    this.running = 'simulate';
    this.progress = null;
    this.showButtons();
    this.bar(0, true);
    this.status('Simulating a walk through the scenario…', 'running');
    const t0 = performance.now();
    try {
      const r = await this.jobs.simulate(this.ctx.app.scenario_json(), SIMULATE_SETTINGS);
      const summary = this.readRecording(r.recording);
      const calSummary = this.readRecording(r.calibration);
      this.rec = { name: 'simulated walk', bytes: r.recording, summary };
      this.cal = { name: 'simulated empty area', bytes: r.calibration, summary: calSummary };
      this.truth = { name: 'simulated truth', text: r.truth, data: parseTruth(r.truth, 'simulated truth') };
      this.s = { ...this.s, calibration: 'file' };
      this.writePanel();
      this.clearResult();
      this.running = null;
      this.ok();
      this.bar(1, false);
      this.status(`Simulated ${summary.snapshots} snapshots × ${summary.links} links in ${fixed((performance.now() - t0) / 1000, 2)} s · press Run`, 'idle');
    } catch (e) {
      this.running = null;
      this.bar(0, false);
      if (e instanceof ChannelStopped) this.status('Simulation stopped', 'stopped');
      else this.fail(`Simulate walk: ${errorText(e)}`);
    }
    this.showInputs();
  },

  /** Estimates and tracks the open recording in the worker. */
  async run() {
    if (!this.rec) {
      this.fail('Run: open, drop or simulate a recording first');
      return;
    }
    if (this.replaying()) return;
    let settings;
    try {
      settings = this.panelSettings();
    } catch (e) {
      this.fail(`Run: ${errorText(e)}`);
      return;
    }
    this.pause();
    const used = { ...this.s };
    const truthText = this.truth ? this.truth.text : null;
    const calibration = this.s.calibration === 'file' && this.cal ? this.cal.bytes : null;
    const scenario = this.ctx.app.scenario_json();
    const nodes = this.ctx.app.nodes();
    const names = nodes.links.map(([k, l]) => `${nodes.transmitters[k].name} → ${nodes.receivers[l].name}`);
    const rec = this.rec;
    this.running = 'run';
    this.progress = null;
    this.progressLog = [];
    this.showButtons();
    this.bar(0, true);
    this.status('Reading the recording…', 'running');
    const t0 = performance.now();
    try {
      const r = await this.jobs.start({
        scenario, recording: rec.bytes,
        calibration,
        truth: truthText,
        targets: used.targets === 'several' ? 'auto' : 'one',
      }, settings, (p) => this.onProgress(p));
      await this.receive(r, { settings: used, truthText, calibration, scenario, names, rec }, t0);
      this.running = null;
      this.showStale();
    } catch (e) {
      this.running = null;
      this.bar(0, false);
      if (e instanceof ChannelStopped) {
        this.status(this.result ? `Stopped · showing the previous run` : 'Stopped', 'stopped');
      } else {
        this.fail(`Run: ${errorText(e)}`);
      }
    }
    this.showButtons();
  },

  /** Stops the running job (simulation or run) or the replay; the result shown stays. */
  stop() {
    if (this.replaying()) {
      this.stopped += 1;
      this.stopReplay();
      return;
    }
    if (!this.running) return;
    this.stopped += 1;
    this.jobs.stop();
  },

  /**
   * A progress report {phase, done, total} of the worker (estimate, track, figure, results) or
   * of the page (load, draw): the bar at the phase's start (its share in RUN_PHASES) plus its
   * part done, the status line the phase's name and count. Kept in progressLog (with the bar).
   */
  onProgress(p) {
    this.progress = p;
    const k = RUN_PHASES.findIndex(([phase]) => phase === p.phase);
    const start = RUN_PHASES.slice(0, Math.max(k, 0)).reduce((a, [, , share]) => a + share, 0);
    const share = k >= 0 ? RUN_PHASES[k][2] : 0;
    const f = p.total > 0 ? Math.min(1, p.done / p.total) : 0;
    const bar = start + f * share;
    this.bar(bar, true);
    this.progressLog.push({ phase: p.phase, done: p.done, total: p.total, bar });
    const name = k >= 0 ? RUN_PHASES[k][1] : p.phase;
    this.status(`${name}…${p.total > 1 ? ` ${p.done} / ${p.total}` : ''}`, 'running');
  },

  /** The progress bar at fraction `f` (animated while `running`). */
  bar(f, running) {
    const b = $('chan-bar');
    b.style.width = `${Math.round(Math.max(0, Math.min(1, f)) * 100)}%`;
    b.classList.toggle('running', running);
  },

  /**
   * A finished run (started at `t0`, performance.now()): the figures (ChannelFigures, read from
   * the worker's texts), the link choice, the charts, the cursor at the start. The reading and
   * the drawing block the page, so each is reported first (progress 'load', 'draw') and a
   * frame is let through to show it; their times are the result's page_ms.
   */
  async receive(r, meta, t0) {
    let fig;
    this.onProgress({ phase: 'load', done: 0, total: 1 });
    await nextPaint();
    const tLoad = performance.now();
    try {
      fig = new this.wasm.ChannelFigures(meta.scenario, r.figure, r.errors, r.track);
    } catch (e) {
      this.fail(`Run: ${errorText(e)}`);
      return;
    }
    const loadMs = performance.now() - tLoad;
    this.onProgress({ phase: 'draw', done: 0, total: 1 });
    await nextPaint();
    const tDraw = performance.now();
    if (this.fig) this.fig.free();
    this.fig = fig;
    this.overlays.clear();
    this.runs += 1;
    this.result = {
      track: JSON.parse(r.track), texts: { track: r.track, figure: r.figure, errors: r.errors, estimates: r.estimates, people: r.people },
      people: r.people ? JSON.parse(r.people) : null,
      timings: { ...r.timings, results_ms: r.ms - sumTimings(r.timings), load_ms: loadMs }, summary: r.summary, ms: r.ms,
      workerWallMs: r.wallMs, wallMs: r.wallMs, ...meta,
    };
    this.stale = [];
    $('chan-figures').classList.remove('stale');
    const sel = $('chan-link');
    sel.replaceChildren(...meta.names.map((n, i) => new Option(n, String(i))));
    if (this.s.link >= meta.names.length) this.s = { ...this.s, link: 0 };
    sel.value = String(this.s.link);
    $('chan-scrub').max = String(this.steps() - 1);
    this.errorText = null;
    clearError();
    this.showButtons();
    this.drawCharts();
    this.seek(Math.min(this.step, this.steps() - 1));
    this.result.timings.draw_ms = performance.now() - tDraw;
    this.result.wallMs = performance.now() - t0;
    this.bar(1, false);
    this.status(this.doneText(), 'done');
  },

  /**
   * The status line of the result shown: the measured times, where the statics came from, the
   * segments (with each loss's reason) and the error statistics.
   */
  doneText() {
    const r = this.result;
    if (!r) return '';
    const t = r.timings || {};
    const s = (ms) => `${fixed(ms / 1000, 2)} s`;
    let text = `Done in ${s(r.wallMs)}: read ${s(t.parse_ms)}, statics and paths ${s(t.estimate_ms)}, `
      + `track ${s(t.track_ms)}, figures ${s(t.figure_ms)}, results and charts ${s((r.wallMs - sumTimings(t)))} · ${this.staticsText()}`;
    if (r.people) return `${text} · ${peopleText(r.people)}`;
    text += ` · ${segmentsText(r.track.segments)}`;
    const e = r.track.error;
    if (e) text += ` · error median ${fixed(e.median_m, 2)} m, 90 % ${fixed(e.p90_m, 2)} m`;
    return text;
  },

  /** Where the result's statics came from and which delays it tracked (ChannelJob.summary()). */
  staticsText() {
    const r = this.result;
    const sum = r.summary || {};
    const cal = sum.calibration || {};
    const how = sum.statics === 'clusters' ? 'static clusters' : 'background';
    let from;
    if (cal.source === 'file') from = `${how} from the empty area's recording (${cal.snapshots} snapshots)`;
    else if (cal.source === 'range') from = `${how} from ${fixed(r.settings.empty_from_s, 2)}–${fixed(r.settings.empty_to_s, 2)} s of the recording (${cal.snapshots} snapshots)`;
    else from = `no empty area: background learnt from the recording (τ = ${fixed(r.settings.background_time_s, 3)} s)`;
    const delays = sum.delay_reference === 'los' ? 'delays relative to the direct path' : 'absolute delays';
    return `${from}, ${delays}`;
  },

  /** Drops the result shown (charts, read-outs, cursor) and says what to do next. */
  clearResult() {
    this.pause();
    this.clearReplay();
    if (this.fig) this.fig.free();
    this.fig = null;
    this.result = null;
    this.stale = [];
    $('chan-figures').classList.remove('stale');
    this.overlays.clear();
    this.step = 0;
    this.drawn = null;
    $('chan-link').replaceChildren();
    $('chan-scrub').max = '0';
    $('chan-scrub').value = '0';
    $('chan-time').textContent = 't = –';
    fillKeyValues($('chan-info'), []);
    this.status(this.rec ? 'Press Run to estimate the paths and track' : 'Open or simulate a recording, then press Run.', 'idle');
    this.bar(0, false);
    this.showButtons();
    this.drawCharts();
    this.redraw();
  },
};
