// The channel view: from channel recordings to a track, in the browser. The user opens or drops
// a recording (.npz) or simulates a walk through the scenario, optionally adds the empty area (a
// recording of it, or a time range of the same recording; without either the background is
// learnt from the recording itself) and the true path (truth.json as the simulator writes it),
// sets the front end's and the tracker's options (the command line's `cir estimate` / `cir
// track` options, with its defaults: channel-settings.js; the worker hands them to the core as
// its ChannelRequest) and presses Run: the estimation and tracking run in a Web Worker
// (channel-job.js) through the core's entry points, with progress and Stop. The track comes in
// segments (the tracker starts by itself, notices a loss, says why and starts again). The
// result is drawn by the core's chart code (ChannelFigures): the delay figure of the chosen link
// ([S] Fig. 4) and the error over time, each with the time cursor; over the error chart this
// file marks the segments (the gaps shaded, each loss with its reason: channel-draw.js
// drawSegments); the map shows the segments up to the cursor, the iso-delay ellipses of the
// delays used, the links used and the filter's 1σ (channel-draw.js). Files are read here with
// File.arrayBuffer() and go to the worker only: nothing leaves the machine.
//
// The state helpers call channelSettings() / applyChannelSettings(obj) (every setting, not the
// recording), checkChannelState(obj) before applying, and leave CHANNEL_TRANSIENT (the cursor's
// snapshot, the playback speed) out of the undo history.

import { $, clip, clearError, errorText, fillKeyValues, fitCanvas, fixed, showError } from './dom.js';
import { ChannelJobs, ChannelStopped } from './channel-job.js';
import { drawChannel, drawCursor, drawSegments, lossName } from './channel-draw.js';
import { CHANNEL_FIELDS, checkChannelSettings, defaultChannelSettings, parseChannelField } from './channel-settings.js';
import { slug } from './export.js';

/** The largest recording file read, bytes (the core's limits::MAX_PAGE_RECORDING_BYTES, 256 MiB). */
export const MAX_RECORDING_FILE_BYTES = 256 * 2 ** 20;
/** The largest truth file read, bytes (the core's limits::MAX_PAGE_TEXT_BYTES, 64 MiB). */
export const MAX_TRUTH_FILE_BYTES = 64 * 2 ** 20;
/** "Simulate walk": the simulator's walk (the scene's) for 15 s, one snapshot every 50 ms. */
export const SIMULATE_SETTINGS = { duration_s: 15, dt_s: 0.05 };

/** The panel's numeric inputs: [setting key, input id, name shown in errors]. */
const INPUTS = [
  ['particles', 'chan-particles', 'particles'],
  ['seed', 'chan-seed', 'seed'],
  ['process_noise', 'chan-q', 'q (process noise)'],
  ['p_fa', 'chan-pfa', 'P_fa'],
  ['max_paths', 'chan-max-paths', 'max paths'],
  ['extent_sigma_m', 'chan-extent', 'extent σ'],
  ['background_time_s', 'chan-bg-time', 'background τ'],
  ['empty_from_s', 'chan-empty-from', 'empty from'],
  ['empty_to_s', 'chan-empty-to', 'empty to'],
];
/** The panel's choices: [setting key, select id]. */
const CHOICES = [['filter', 'chan-filter'], ['calibration', 'chan-cal-source'], ['statics', 'chan-statics'],
  ['delay_reference', 'chan-delay-ref'], ['speed', 'chan-speed']];
/** The settings a run depends on (a change after a run says so). */
const RUN_KEYS = ['filter', 'particles', 'seed', 'process_noise', 'p_fa', 'max_paths', 'extent_sigma_m',
  'statics', 'delay_reference', 'background_time_s', 'calibration', 'empty_from_s', 'empty_to_s'];
/** The run's settings as the status line names them when they change. */
const RUN_LABELS = {
  filter: 'filter', particles: 'particles', seed: 'seed', process_noise: 'q', p_fa: 'P_fa', max_paths: 'max paths',
  extent_sigma_m: 'extent σ', statics: 'statics', delay_reference: 'delays', background_time_s: 'background τ',
  calibration: 'empty area', empty_from_s: 'empty from', empty_to_s: 'empty to',
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
 * The phases of a run in order: [phase, name in the status line, share of the progress bar].
 * The worker reports estimate (link-snapshots), track, figure (links) and results (its texts
 * being written); the page load (reading them into ChannelFigures) and draw (the charts). The
 * shares are the measured split of a 1528-snapshot, 4-link recording (issue 38 item 9, see
 * docs/page.md; the --dev build: reading and estimates 3.6 s, track 0.2 s, figure 0.3 s,
 * results 1.3 s, reading them 0.5 s, charts 0.8 s): before, the bar sat at 95 % with the last
 * estimate count while the rest took as long again.
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

let instance = null;

/**
 * The settings that are not edits: the time cursor's snapshot and the playback speed. They are
 * saved and linked, but stepping the cursor, Play and a new speed add no undo step, and an undo
 * leaves them where they are (state.js `transient`; the tracking view's step and speed alike).
 */
export const CHANNEL_TRANSIENT = ['step', 'speed'];

/**
 * Checks the page state's channel section strictly (checkChannelSettings) before anything is
 * applied; throws an Error naming the field as `state.channel.<key>: …`.
 */
export function checkChannelState(obj) {
  try {
    checkChannelSettings(obj);
  } catch (e) {
    throw new Error(errorText(e).replace(/^channel settings?(?: (\w+))?:/, (_, k) => (k ? `state.channel.${k}:` : 'state.channel:')));
  }
}

/** Every setting of the channel view as a plain JSON object (not the recording itself). */
export function channelSettings() {
  if (!instance) throw new Error('channel view: not started yet');
  return instance.settings();
}

/**
 * Checks `obj` strictly (channel-settings.js checkChannelSettings, then the link and the step
 * against the result shown) and applies it; throws a named Error and changes nothing if it
 * is not valid.
 */
export function applyChannelSettings(obj) {
  if (!instance) throw new Error('channel view: not started yet');
  instance.applySettings(obj);
}

/** A file's bytes, checked against `max` before reading; throws naming `what` and the file. */
async function readBytes(file, max, what) {
  if (file.size > max) {
    throw new Error(`${what} ${clip(file.name)}: ${file.size} bytes, more than the ${max} bytes the page reads`);
  }
  return new Uint8Array(await file.arrayBuffer());
}

/** A truth file's text, parsed: {t_s, states: [[x, y, vx, vy]…]}; throws naming the file and the field. */
function parseTruth(text, name) {
  let t;
  try {
    t = JSON.parse(text);
  } catch (e) {
    throw new Error(`truth file ${clip(name)}: not JSON (${errorText(e)})`);
  }
  if (!t || typeof t !== 'object' || !Array.isArray(t.t_s) || !Array.isArray(t.states)) {
    throw new Error(`truth file ${clip(name)}: needs the arrays t_s and states (the simulator's truth.json)`);
  }
  if (t.states.length !== t.t_s.length) {
    throw new Error(`truth file ${clip(name)}: ${t.states.length} states for ${t.t_s.length} times (one state per time)`);
  }
  const bad = t.states.findIndex((s) => !Array.isArray(s) || s.length !== 4 || !s.every((v) => typeof v === 'number' && Number.isFinite(v)));
  if (bad >= 0) throw new Error(`truth file ${clip(name)}: states[${bad}] is not [x, y, vx, vy] (four finite numbers)`);
  return t;
}

export class Channel {
  /** @param {object} ctx - {app, wasm, module, st, view, changed, figures} (app.js). */
  constructor(ctx) {
    this.ctx = ctx;
    this.wasm = ctx.wasm;
    this.jobs = new ChannelJobs(ctx.module);
    this.s = defaultChannelSettings();
    this.rec = null; // {name, bytes, summary}
    this.cal = null; // {name, bytes, summary}
    this.truth = null; // {name, text, data}
    this.result = null; // {track (object), texts {track, figure, errors, estimates}, timings, summary, ms, wallMs, settings, names, scenario}
    this.fig = null; // wasm ChannelFigures of the result
    this.step = 0;
    this.pos = 0; // time position while playing, s
    this.playing = false;
    this.running = null; // 'run' | 'simulate' | null
    this.progress = null; // the last {phase, done, total}
    this.stopped = 0; // jobs stopped so far
    this.runs = 0; // results received
    this.errorText = null; // the last error of a run or a file
    this.drawn = null; // what the map overlay drew last (drawChannel)
    this.delayBox = null; // the delay chart's plot box (cursor), backing pixels
    this.errorBox = null;
    this.segmentMarks = null; // what drawSegments drew over the error chart
    this.cursorX = { delays: null, errors: null };
    this.overlays = new Map(); // step -> ChannelFigures.overlay(step)
    this.stale = []; // what changed since the result shown (staleReasons)
    this.progressLog = []; // every progress report of the last run: {phase, done, total, bar}
    this.tickFn = (now) => this.tick(now);
    instance = this;
    this.bind();
    this.writePanel();
    this.showInputs();
    this.showButtons();
  }

  active() { return this.ctx.st.mode === 'channel'; }

  // ---------- settings ----------

  /** The settings now (a fresh plain object). */
  settings() {
    return { ...this.s, step: this.step };
  }

  /** Checks `obj` strictly and applies it (see applyChannelSettings). */
  applySettings(obj) {
    const s = checkChannelSettings(obj);
    if (this.result) {
      const links = this.result.names.length;
      if (s.link >= links) throw new Error(`channel setting link: ${s.link} is out of range (the result has links 0 … ${links - 1})`);
      const last = this.steps() - 1;
      if (s.step > last) throw new Error(`channel setting step: ${s.step} is out of range (the result has snapshots 0 … ${last})`);
    }
    this.s = s;
    this.writePanel();
    for (const [, id] of INPUTS) $(id).classList.remove('invalid');
    if (this.result) {
      $('chan-link').value = String(s.link);
      this.drawCharts();
      this.seek(s.step);
    } else {
      this.step = s.step;
    }
    this.showStale();
  }

  /** The panel's inputs from this.s. */
  writePanel() {
    for (const [key, id] of INPUTS) if (document.activeElement !== $(id)) $(id).value = String(this.s[key]);
    for (const [key, id] of CHOICES) $(id).value = String(this.s[key]);
    const pf = this.s.filter === 'pf';
    $('chan-particles-wrap').hidden = !pf;
    $('chan-seed-wrap').hidden = !pf;
    const src = this.s.calibration;
    $('chan-cal-file-wrap').hidden = src !== 'file';
    $('chan-cal-clear-wrap').hidden = src !== 'file';
    $('chan-empty-from-wrap').hidden = src !== 'range';
    $('chan-empty-to-wrap').hidden = src !== 'range';
    $('chan-filter-label').textContent = this.s.filter.toUpperCase();
  }

  /** One input edited: parse it strictly into this.s, or name the error and keep the old value. */
  editInput(key, id, label) {
    const el = $(id);
    try {
      const v = parseChannelField(key, el.value, label);
      const next = checkChannelSettings({ ...this.s, [key]: v });
      this.s = next;
      el.classList.remove('invalid');
      // A corrected range clears its partner's mark too.
      if (key === 'empty_from_s' || key === 'empty_to_s') {
        $('chan-empty-from').classList.remove('invalid');
        $('chan-empty-to').classList.remove('invalid');
      }
      clearError();
      this.showStale();
    } catch (e) {
      el.classList.add('invalid');
      showError(errorText(e));
    }
    this.showInputs();
  }

  bind() {
    for (const [key, id, label] of INPUTS) {
      $(id).setAttribute('inputmode', 'decimal');
      $(id).setAttribute('autocomplete', 'off');
      $(id).addEventListener('change', () => this.editInput(key, id, label));
    }
    // The "Empty area" line follows its from/to fields as they are typed.
    for (const id of ['chan-empty-from', 'chan-empty-to']) $(id).addEventListener('input', () => this.showInputs());
    $('chan-filter').addEventListener('change', () => {
      this.s = { ...this.s, filter: $('chan-filter').value };
      this.writePanel();
      this.showStale();
    });
    for (const [key, id] of [['statics', 'chan-statics'], ['delay_reference', 'chan-delay-ref']]) {
      $(id).addEventListener('change', () => {
        this.s = { ...this.s, [key]: $(id).value };
        this.showInputs();
        this.showStale();
      });
    }
    $('chan-cal-clear').addEventListener('click', () => {
      this.cal = null;
      this.showInputs();
      this.showStale();
    });
    $('chan-cal-source').addEventListener('change', () => {
      this.s = { ...this.s, calibration: $('chan-cal-source').value };
      this.writePanel();
      this.showInputs();
      this.showStale();
    });
    $('chan-speed').addEventListener('change', () => {
      this.s = { ...this.s, speed: Number($('chan-speed').value) };
    });
    $('chan-link').addEventListener('change', () => {
      this.s = { ...this.s, link: Number($('chan-link').value) };
      this.drawCharts();
    });
    $('chan-file').addEventListener('change', () => this.fileInput('chan-file', (f) => this.openRecording(f)));
    $('chan-cal-file').addEventListener('change', () => this.fileInput('chan-cal-file', (f) => this.openCalibration(f)));
    $('chan-truth-file').addEventListener('change', () => this.fileInput('chan-truth-file', (f) => this.openTruth(f)));
    $('chan-truth-clear').addEventListener('click', () => {
      this.truth = null;
      this.showInputs();
      this.showStale();
      this.redraw();
    });
    $('chan-simulate').addEventListener('click', () => this.simulate());
    $('chan-run').addEventListener('click', () => this.run());
    $('chan-stop').addEventListener('click', () => this.stop());
    $('chan-play').addEventListener('click', () => (this.playing ? this.pause() : this.play()));
    $('chan-scrub').addEventListener('input', () => {
      const n = Number($('chan-scrub').value); // before pause() redraws the transport (and the slider)
      this.pause();
      this.seek(n);
    });
    $('chan-save').addEventListener('click', () => this.save($('chan-save-what').value));
    // Drop files onto the map or the channel panel.
    for (const el of [$('plot').parentElement, $('chan-section')]) {
      el.addEventListener('dragover', (ev) => {
        if (!this.active() || !ev.dataTransfer || ![...ev.dataTransfer.types].includes('Files')) return;
        ev.preventDefault();
        ev.dataTransfer.dropEffect = 'copy';
        $('plot').parentElement.classList.add('chan-drop');
      });
      el.addEventListener('dragleave', () => $('plot').parentElement.classList.remove('chan-drop'));
      el.addEventListener('drop', (ev) => {
        $('plot').parentElement.classList.remove('chan-drop');
        if (!this.active() || !ev.dataTransfer) return;
        ev.preventDefault();
        this.dropFiles([...ev.dataTransfer.files]);
      });
    }
    const redrawCharts = () => { if (this.active()) this.drawCharts(); };
    new ResizeObserver(redrawCharts).observe($('chan-delays').parentElement);
    new ResizeObserver(redrawCharts).observe($('chan-errors').parentElement);
  }

  /** A file input's file through `open` (then the input is emptied, so the same file can be chosen again). */
  async fileInput(id, open) {
    const input = $(id);
    const f = input.files && input.files[0];
    if (!f) return;
    await open(f);
    input.value = '';
  }

  /**
   * Dropped files: a .json is the truth, the first .npz the recording and a second one the
   * empty area's recording (the calibration source becomes "recording").
   */
  async dropFiles(files) {
    const npz = files.filter((f) => /\.npz$/i.test(f.name));
    const json = files.filter((f) => /\.json$/i.test(f.name));
    const other = files.filter((f) => !npz.includes(f) && !json.includes(f));
    if (other.length) {
      this.fail(`Dropped file ${clip(other[0].name)}: not a recording (.npz) or a truth file (.json)`);
      return;
    }
    if (npz[0]) await this.openRecording(npz[0]);
    if (npz[1]) await this.openCalibration(npz[1]);
    if (json[0]) await this.openTruth(json[0]);
  }

  /**
   * A recording's bytes read and checked as the job checks them at Run (the core's reader, its
   * links against the scenario's: channel_recording_summary). Returns the summary {snapshots,
   * links, layout, samples_per_link, duration_s, t_s}; throws the core's named error.
   */
  readRecording(bytes) {
    return this.wasm.channel_recording_summary(this.ctx.app.scenario_json(), bytes);
  }

  /**
   * The open truth file checked against the recording's times (the core's check at Run,
   * check_channel_truth); throws naming both files. Nothing without both.
   */
  checkTruth(truth, rec) {
    if (!truth || !rec) return;
    try {
      this.wasm.check_channel_truth(truth.text, new Float64Array(rec.summary.t_s));
    } catch (e) {
      throw new Error(`truth file ${clip(truth.name)} does not fit the recording ${clip(rec.name)} (${rec.summary.snapshots} snapshots): ${errorText(e)}`);
    }
  }

  /**
   * Reads and checks a recording (the core's reader and its links against the scenario's, named
   * errors) and replaces the one open. A result shown stays, marked stale. A truth file open
   * that does not fit the new recording is dropped, and the banner says so.
   */
  async openRecording(file) {
    try {
      const bytes = await readBytes(file, MAX_RECORDING_FILE_BYTES, 'recording');
      const summary = this.readRecording(bytes);
      this.rec = { name: file.name, bytes, summary };
      if (!this.result) this.clearResult();
      this.ok();
      try {
        this.checkTruth(this.truth, this.rec);
      } catch (e) {
        this.truth = null;
        this.fail(`Recording ${clip(file.name)} opened; its ${errorText(e)} — the truth file was dropped (open the one of this recording)`);
      }
    } catch (e) {
      this.fail(`Recording ${clip(file.name)}: ${errorText(e)}`);
    }
    this.showInputs();
    this.showStale();
    this.redraw();
  }

  /** Reads and checks the empty area's recording; the calibration source becomes "recording". */
  async openCalibration(file) {
    try {
      const bytes = await readBytes(file, MAX_RECORDING_FILE_BYTES, 'empty-area recording');
      const summary = this.readRecording(bytes);
      this.cal = { name: file.name, bytes, summary };
      this.s = { ...this.s, calibration: 'file' };
      this.writePanel();
      this.ok();
    } catch (e) {
      this.fail(`Empty-area recording ${clip(file.name)}: ${errorText(e)}`);
    }
    this.showInputs();
    this.showStale();
  }

  /**
   * Reads and checks a truth file: its form here, its times against the open recording's by the
   * core's check (as at Run), so a file of another length is refused at open, naming both.
   */
  async openTruth(file) {
    try {
      if (file.size > MAX_TRUTH_FILE_BYTES) {
        throw new Error(`${file.size} bytes, more than the ${MAX_TRUTH_FILE_BYTES} bytes the page reads`);
      }
      const text = await file.text();
      const truth = { name: file.name, text, data: parseTruth(text, file.name) };
      this.checkTruth(truth, this.rec);
      this.truth = truth;
      this.ok();
    } catch (e) {
      this.fail(e.message.startsWith('truth file') ? errorText(e) : `Truth file ${clip(file.name)}: ${errorText(e)}`);
    }
    this.showInputs();
    this.showStale();
    this.redraw();
  }

  ok() {
    this.errorText = null;
    clearError();
  }

  /** Names an error in the banner and the status line. */
  fail(message) {
    this.errorText = message;
    showError(message);
    this.status(message, 'error');
  }

  /** The files read-out and the controls that need them. */
  showInputs() {
    const rows = [];
    const sum = (s) => `${s.snapshots} snapshots × ${s.links} links × ${s.samples_per_link} ${s.layout === 'cfr' ? 'frequencies' : 'taps'}, ${fixed(s.duration_s, 2)} s`;
    rows.push(['Recording', this.rec ? `${this.rec.name} · ${sum(this.rec.summary)}` : '—', '']);
    if (this.s.calibration === 'file') rows.push(['Empty area', this.cal ? `${this.cal.name} · ${sum(this.cal.summary)}` : this.noEmptyText(), '']);
    else rows.push(['Empty area', this.emptyRangeText(), '']);
    rows.push(['Truth', this.truth ? `${this.truth.name} · ${this.truth.data.t_s.length} states` : '— (optional)', '']);
    fillKeyValues($('chan-inputs'), rows);
    $('chan-truth-clear').disabled = !this.truth;
    $('chan-cal-clear').disabled = !this.cal;
    this.showButtons();
  }

  /**
   * The "Empty area" line of a time range: the from/to fields as they stand (also while typed,
   * before Enter), with the recording's snapshots inside, or what is wrong with them.
   */
  emptyRangeText() {
    const field = (key, id, label) => {
      try {
        return { v: parseChannelField(key, $(id).value, label) };
      } catch (e) {
        return { error: errorText(e) };
      }
    };
    const from = field('empty_from_s', 'chan-empty-from', 'from');
    const to = field('empty_to_s', 'chan-empty-to', 'to');
    if (from.error || to.error) return from.error || to.error;
    const range = `${fixed(from.v, 3)} … ${fixed(to.v, 3)} s`;
    if (!(to.v > from.v)) return `${range}: "to" must be after "from"`;
    if (!this.rec) return `${range} of the recording`;
    const n = this.rec.summary.t_s.filter((t) => t >= from.v && t <= to.v).length;
    return `${range} of the recording (${n ? `${n} snapshot${n === 1 ? '' : 's'}` : 'no snapshot: choose times of the recording'})`;
  }

  /** The read-out of the empty area without its recording (the file is optional). */
  noEmptyText() {
    if (this.s.statics === 'clusters') {
      return 'none — statics "clusters" needs one: open the empty area\'s recording, choose a time range, or use statics "background"';
    }
    return `none (optional) — the background is learnt from the recording itself (τ = ${fixed(this.s.background_time_s, 3)} s)`;
  }

  showButtons() {
    const busy = this.running !== null;
    $('chan-run').disabled = busy || !this.rec;
    $('chan-stop').disabled = !busy;
    $('chan-simulate').disabled = busy;
    const has = !!this.result;
    $('chan-save').disabled = !has;
    $('chan-play').disabled = !has;
    $('chan-scrub').disabled = !has;
    $('chan-link').disabled = !has;
  }

  /** The status line (`state`: idle, running, done, error, stopped). */
  status(text, state) {
    const el = $('chan-status');
    el.textContent = text;
    el.dataset.state = state;
  }

  /**
   * What differs now from the inputs of the result shown, each named for the status line
   * ("Rx2 moved", "P_fa changed", "recording walk.npz opened", …); empty when it is current or
   * there is none (issue 38 item 6: any change that invalidates a result marks it stale).
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
  }

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
  }

  // ---------- jobs ----------

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
    if (s.delay_reference !== 'auto') out.delay_reference = s.delay_reference;
    if (s.filter === 'pf') Object.assign(out, { particles: s.particles, seed: s.seed });
    if (s.calibration === 'range') out.calibration_range_s = [s.empty_from_s, s.empty_to_s];
    return out;
  }

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
  }

  /** Estimates and tracks the open recording in the worker. */
  async run() {
    if (!this.rec) {
      this.fail('Run: open, drop or simulate a recording first');
      return;
    }
    let settings;
    try {
      // The panel's text as it stands (an input not yet committed with Enter counts too).
      for (const [key, id, label] of INPUTS) {
        const v = parseChannelField(key, $(id).value, label);
        this.s = checkChannelSettings({ ...this.s, [key]: v });
      }
      settings = this.jobSettings();
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
  }

  /** Stops the running job (simulation or run); the result shown stays. */
  stop() {
    if (!this.running) return;
    this.stopped += 1;
    this.jobs.stop();
  }

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
  }

  bar(f, running) {
    const b = $('chan-bar');
    b.style.width = `${Math.round(Math.max(0, Math.min(1, f)) * 100)}%`;
    b.classList.toggle('running', running);
  }

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
      track: JSON.parse(r.track), texts: { track: r.track, figure: r.figure, errors: r.errors, estimates: r.estimates },
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
  }

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
    text += ` · ${segmentsText(r.track.segments)}`;
    const e = r.track.error;
    if (e) text += ` · error median ${fixed(e.median_m, 2)} m, 90 % ${fixed(e.p90_m, 2)} m`;
    return text;
  }

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
  }

  clearResult() {
    this.pause();
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
  }

  // ---------- time cursor ----------

  steps() { return this.result ? this.result.track.t_s.length : 0; }

  /** The overlay of snapshot k (cached). */
  overlay(k) {
    if (!this.fig) return null;
    if (!this.overlays.has(k)) this.overlays.set(k, this.fig.overlay(k));
    return this.overlays.get(k);
  }

  /** Moves the cursor to snapshot n (clamped): map, read-outs, chart cursors. */
  seek(n) {
    if (!this.result) return;
    this.step = Math.max(0, Math.min(Math.round(n), this.steps() - 1));
    this.pos = this.result.track.t_s[this.step];
    this.show();
    this.drawCursors();
    this.redraw();
  }

  redraw() { this.ctx.changed({ frame: true }); }

  play() {
    if (!this.result) return;
    if (this.step >= this.steps() - 1) this.seek(0);
    this.playing = true;
    this.pos = this.result.track.t_s[this.step];
    this.last = performance.now();
    requestAnimationFrame(this.tickFn);
    this.show();
  }

  pause() {
    if (!this.playing) return;
    this.playing = false;
    this.show();
  }

  tick(now) {
    if (!this.playing || !this.result) return;
    const t = this.result.track.t_s;
    this.pos += ((now - this.last) / 1000) * this.s.speed;
    this.last = now;
    let n = this.step;
    while (n + 1 < t.length && t[n + 1] <= this.pos) n += 1;
    if (n >= t.length - 1) this.playing = false;
    if (n !== this.step) {
      this.step = n;
      this.show();
      this.drawCursors();
      this.redraw();
    } else {
      this.show();
    }
    if (this.playing) requestAnimationFrame(this.tickFn);
  }

  /** The transport and the read-outs of the cursor's snapshot. */
  show() {
    $('chan-play').textContent = this.playing ? '❚❚ Pause' : '▶ Play';
    $('chan-play').dataset.playing = this.playing ? '1' : '0';
    if (!this.result) return;
    const tr = this.result.track;
    const n = this.steps() - 1;
    $('chan-scrub').value = String(this.step);
    $('chan-scrub').setAttribute('aria-valuetext', `t = ${fixed(tr.t_s[this.step], 2)} s, snapshot ${this.step} of ${n}`);
    const time = $('chan-time');
    time.textContent = `t = ${fixed(tr.t_s[this.step], 2)} s / ${fixed(tr.t_s[n], 2)} s · snapshot ${this.step}/${n}`;
    Object.assign(time.dataset, { step: String(this.step), t: String(tr.t_s[this.step]) });
    const ov = this.overlay(this.step);
    const m2 = (p) => (p ? `${fixed(p[0], 3)}, ${fixed(p[1], 3)} m` : '—');
    const truth = this.truthAt(this.step);
    const e = ov.sigma_ellipse;
    const seg = this.segmentAt(this.step);
    const rows = [
      [`${(tr.filter || this.result.settings.filter).toUpperCase()} estimate`, ov.state ? m2(ov.state) : seg.text, 'fix'],
      ['Segment', ov.segment === null || ov.segment === undefined ? '—'
        : `${ov.segment + 1} of ${tr.segments.length} (${fixed(tr.segments[ov.segment].t_first_s, 2)}–${fixed(tr.segments[ov.segment].t_last_s, 2)} s)`, ''],
      ['1σ ellipse', e ? `${fixed(e.a, 3)} × ${fixed(e.b, 3)} m` : '—', 'fix'],
      ['Truth', m2(truth), ''],
      ['Error', ov.error_m === null || ov.error_m === undefined ? '—' : `${fixed(ov.error_m, 3)} m`, 'fix'],
      ['Links used', ov.links.length ? ov.links.map((l) => this.result.names[l.link] || `link ${l.link}`).join(', ') : 'none', ''],
    ];
    fillKeyValues($('chan-info'), rows);
  }

  /**
   * What the track is doing at snapshot k outside its segments: {text} ("searching (not started
   * yet)", "lost at 7.35 s (outside area) · searching", "ended").
   */
  segmentAt(k) {
    const tr = this.result.track;
    const segs = tr.segments || [];
    const before = segs.filter((g) => g.last < k);
    if (!before.length) return { text: segs.length ? 'searching (not started yet)' : 'never started' };
    const g = before[before.length - 1];
    const t = tr.t_s[Math.min(g.last + 1, tr.t_s.length - 1)];
    return { text: g.end === 'end' ? 'ended' : `lost at ${fixed(t, 2)} s (${lossName(g.end)}) · searching` };
  }

  /** The true position at snapshot k ([x, y]) when a truth file of the run is at hand. */
  truthAt(k) {
    if (!this.truth || !this.result || this.truth.text !== this.result.truthText) return null;
    const s = this.truth.data.states[k];
    return s ? [s[0], s[1]] : null;
  }

  /** Mode switch: redraw the charts (their size may have changed while hidden), or pause. */
  setActive(on) {
    if (on) {
      this.drawCharts();
      this.showInputs();
    } else {
      this.pause();
    }
  }

  // ---------- drawing ----------

  /** The map layer (app.js sets it as the scene's overlay in this view). */
  overlayLayer(ctx, view) {
    if (!this.result) {
      this.drawn = null;
      return;
    }
    // A node moved (or the scenario changed) since the run: say so before drawing it stale.
    this.showStale(true);
    const truth = this.truthAt(0) ? this.truth.data.states.map((s) => [s[0], s[1]]) : null;
    this.drawn = drawChannel(ctx, view, {
      overlay: this.overlay(this.step), truth, step: this.step, nodes: this.ctx.st.nodes,
      stale: this.stale.length > 0,
    });
  }

  /** The delay figure of the chosen link and the error chart, by the core's chart code. */
  drawCharts() {
    for (const id of ['chan-delays', 'chan-errors']) {
      const c = $(id);
      fitCanvas(c);
      if (!this.fig) c.getContext('2d').clearRect(0, 0, c.width, c.height);
    }
    this.delayBox = null;
    this.errorBox = null;
    this.segmentMarks = null;
    if (this.fig && this.active()) {
      try {
        const r = this.result;
        const link = this.s.link;
        this.delayBox = this.fig.draw_link_delays($('chan-delays'), link, 'Delays of one link', '');
        this.errorBox = this.fig.draw_error_time($('chan-errors'), 'Position error over time', '');
        // The segments over the core's chart (gaps shaded, each loss and its reason).
        this.segmentMarks = drawSegments($('chan-errors'), this.errorBox, r.track.segments || [], r.track.t_s);
      } catch (e) {
        showError(`Channel figures: ${errorText(e)}`);
        console.error(e);
      }
    }
    this.drawCursors();
  }

  /** The time cursor on both charts. */
  drawCursors() {
    const t = this.result ? this.result.track.t_s[this.step] : null;
    for (const [key, id, box] of [['delays', 'chan-delays', this.delayBox], ['errors', 'chan-errors', this.errorBox]]) {
      const c = $(id);
      this.cursorX[key] = drawCursor($(`${id}-cursor`), box, t, c.width, c.height);
    }
  }

  // ---------- saving ----------

  /** Saves `what` (the options of #chan-save-what) through export.js' download (so its hooks see it). */
  async save(what) {
    const figures = this.ctx.figures;
    const t0 = performance.now();
    try {
      if (!this.result) throw new Error('nothing to save yet: run the estimation first');
      const base = `${slug(this.ctx.app.scenario().name)}-channel`;
      const linkSlug = slug(this.result.names[this.s.link] || `link-${this.s.link}`);
      let blob;
      let name;
      if (what === 'delays-svg') {
        blob = new Blob([this.fig.delays_svg(0, 0, 'Delay estimates per link ([S] Fig. 4)', this.subtitle())], { type: 'image/svg+xml' });
        name = `${base}-delays.svg`;
      } else if (what === 'errors-svg') {
        blob = new Blob([this.fig.errors_svg(0, 0, `Track from channel recordings (${this.result.settings.filter.toUpperCase()})`, this.subtitle())], { type: 'image/svg+xml' });
        name = `${base}-track-figure.svg`;
      } else if (what === 'delays-png' || what === 'errors-png' || what === 'map-png') {
        const id = { 'delays-png': 'chan-delays', 'errors-png': 'chan-errors', 'map-png': 'plot' }[what];
        blob = await new Promise((resolve, reject) => {
          $(id).toBlob((b) => (b ? resolve(b) : reject(new Error('the canvas gave no image'))), 'image/png');
        });
        name = { 'delays-png': `${base}-delays-${linkSlug}.png`, 'errors-png': `${base}-errors.png`, 'map-png': `${base}-map.png` }[what];
      } else if (what === 'track-json') {
        // The file `cir track --out` writes (its text ends in a newline).
        blob = new Blob([`${this.result.texts.track}\n`], { type: 'application/json' });
        name = `${base}-track.json`;
      } else {
        throw new Error(`"${clip(what)}" is not something to save`);
      }
      figures.download(blob, name, { mode: 'channel', what, format: name.split('.').pop(), ms: performance.now() - t0 });
      const btn = $('chan-save');
      btn.dataset.saved = name;
      btn.dataset.count = String(Number(btn.dataset.count || 0) + 1);
    } catch (e) {
      showError(`Save: ${errorText(e)}`);
    }
  }

  /** The figures' subtitle: scenario, snapshots, filter. */
  subtitle() {
    const r = this.result;
    return `${this.ctx.app.scenario().name} · ${r.track.t_s.length} snapshots · ${r.settings.filter.toUpperCase()} · grey: static clusters (±3σ) · dashed: truth`;
  }

  // ---------- hooks ----------

  /** Test and console hook (read-only numbers). */
  state() {
    const r = this.result;
    return {
      mode: this.ctx.st.mode,
      running: this.running,
      progress: this.progress,
      runs: this.runs,
      stopped: this.stopped,
      status: $('chan-status').textContent,
      statusState: $('chan-status').dataset.state,
      stale: this.stale.slice(),
      progressLog: this.progressLog.map((p) => ({ ...p })),
      error: this.errorText,
      recording: this.rec ? { name: this.rec.name, ...this.rec.summary } : null,
      calibration: this.cal ? { name: this.cal.name, ...this.cal.summary } : null,
      truth: this.truth ? this.truth.name : null,
      steps: this.steps(),
      step: this.step,
      t_s: r ? r.track.t_s[this.step] : null,
      playing: this.playing,
      drawn: this.drawn,
      cursorX: { ...this.cursorX },
      delayBox: this.delayBox,
      errorBox: this.errorBox,
      segments: r ? (r.track.segments || []).map((g) => ({ first: g.first, last: g.last, t_first_s: g.t_first_s, t_last_s: g.t_last_s, end: g.end })) : null,
      segmentMarks: this.segmentMarks,
      statics: r ? { ...r.summary.calibration, statics: r.summary.statics, delay_reference: r.summary.delay_reference } : null,
      links: r ? r.names.slice() : [],
      timings: r ? r.timings : null,
      wallMs: r ? r.wallMs : null,
      workerMs: r ? r.ms : null,
      settings: this.settings(),
    };
  }

  /** The result's texts (TRACK.json, EST.json, the figure and error views) for the tests, or null. */
  texts() {
    return this.result ? { ...this.result.texts } : null;
  }
}

/** The settings' keys (for the state helper's documentation and tests). */
export const CHANNEL_SETTING_KEYS = CHANNEL_FIELDS.map((f) => f[0]);
