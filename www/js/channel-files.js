// The channel view's files and settings (a part of the Channel class, channel.js): the settings
// panel (read strictly through channel-settings.js), opening or dropping the recording, the empty
// area's recording and the truth file (each checked by the core as at Run), and the read-out of
// the files. Files are read with File.arrayBuffer() and go to the worker only.

import { $, clip, clearError, errorText, fillKeyValues, fixed, showError } from './dom.js';
import { checkChannelSettings, parseChannelField } from './channel-settings.js';

/** The largest recording file read, bytes (the core's limits::MAX_PAGE_RECORDING_BYTES, 256 MiB). */
export const MAX_RECORDING_FILE_BYTES = 256 * 2 ** 20;
/** A recording's file name: `.npz` (docs/recording.md) or a Wi-Fi CSI tool's file (the core
 * tells the format by its first bytes). */
export const RECORDING_FILE = /\.(npz|dat|pcap|csi|csv)$/i;
/** The largest truth file read, bytes (the core's limits::MAX_PAGE_TEXT_BYTES, 64 MiB). */
export const MAX_TRUTH_FILE_BYTES = 64 * 2 ** 20;

/** The panel's numeric inputs: [setting key, input id, name shown in errors]. */
export const INPUTS = [
  ['particles', 'chan-particles', 'particles'],
  ['seed', 'chan-seed', 'seed'],
  ['process_noise', 'chan-q', 'q (process noise)'],
  ['p_fa', 'chan-pfa', 'P_fa'],
  ['max_paths', 'chan-max-paths', 'max paths'],
  ['extent_sigma_m', 'chan-extent', 'extent σ'],
  ['background_time_s', 'chan-bg-time', 'background τ'],
  ['cpi_snapshots', 'chan-cpi', 'CPI snapshots'],
  ['range_rate_floor_mps', 'chan-rr-floor', 'range-rate floor'],
  ['empty_from_s', 'chan-empty-from', 'empty from'],
  ['empty_to_s', 'chan-empty-to', 'empty to'],
];
/** The panel's choices: [setting key, select id]. */
export const CHOICES = [['filter', 'chan-filter'], ['calibration', 'chan-cal-source'], ['statics', 'chan-statics'],
  ['delay_reference', 'chan-delay-ref'], ['speed', 'chan-speed'], ['targets', 'chan-targets']];

/** A file's bytes, checked against `max` before reading; throws naming `what` and the file. */
async function readBytes(file, max, what) {
  if (file.size > max) {
    throw new Error(`${what} ${clip(file.name)}: ${file.size} bytes, more than the ${max} bytes the page reads`);
  }
  return new Uint8Array(await file.arrayBuffer());
}

/** A truth file's text, parsed: {t_s, states: [[x, y, vx, vy]…]}; throws naming the file and the field. */
export function parseTruth(text, name) {
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

/** The files and settings part of the Channel class (channel.js mixes it in). */
export const channelFiles = {
  /** The settings now (a fresh plain object). */
  settings() {
    return { ...this.s, step: this.step };
  },

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
  },

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
  },

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
  },

  /** The settings' inputs and choices, the file inputs, Clear and dropping files onto the map or the panel. */
  bindFiles() {
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
    $('chan-file').addEventListener('change', () => this.fileInput('chan-file', (f) => this.openRecording(f)));
    $('chan-cal-file').addEventListener('change', () => this.fileInput('chan-cal-file', (f) => this.openCalibration(f)));
    $('chan-truth-file').addEventListener('change', () => this.fileInput('chan-truth-file', (f) => this.openTruth(f)));
    $('chan-truth-clear').addEventListener('click', () => {
      this.truth = null;
      this.showInputs();
      this.showStale();
      this.redraw();
    });
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
  },

  /** A file input's file through `open` (then the input is emptied, so the same file can be chosen again). */
  async fileInput(id, open) {
    const input = $(id);
    const f = input.files && input.files[0];
    if (!f) return;
    await open(f);
    input.value = '';
  },

  /**
   * Dropped files: a .json is the truth, the first recording (.npz, or a Wi-Fi CSI tool's
   * .dat/.pcap/.csi/.csv: RECORDING_FILE) the recording and a second one the empty area's
   * recording (the calibration source becomes "recording").
   */
  async dropFiles(files) {
    const npz = files.filter((f) => RECORDING_FILE.test(f.name));
    const json = files.filter((f) => /\.json$/i.test(f.name));
    const other = files.filter((f) => !npz.includes(f) && !json.includes(f));
    if (other.length) {
      this.fail(`Dropped file ${clip(other[0].name)}: not a recording (.npz, .dat, .pcap, .csi, .csv) or a truth file (.json)`);
      return;
    }
    if (npz[0]) await this.openRecording(npz[0]);
    if (npz[1]) await this.openCalibration(npz[1]);
    if (json[0]) await this.openTruth(json[0]);
  },

  /**
   * A recording's bytes read and checked as the job checks them at Run (the core's reader, its
   * links against the scenario's: channel_recording_summary). Returns the summary {snapshots,
   * links, layout, samples_per_link, duration_s, t_s}; throws the core's named error.
   */
  readRecording(bytes) {
    return this.wasm.channel_recording_summary(this.ctx.app.scenario_json(), bytes);
  },

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
  },

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
  },

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
  },

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
  },

  /** A file or a run went well: no error named. */
  ok() {
    this.errorText = null;
    clearError();
  },

  /** Names an error in the banner and the status line. */
  fail(message) {
    this.errorText = message;
    showError(message);
    this.status(message, 'error');
  },

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
  },

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
  },

  /** The read-out of the empty area without its recording (the file is optional). */
  noEmptyText() {
    if (this.s.statics === 'clusters') {
      return 'none — statics "clusters" needs one: open the empty area\'s recording, choose a time range, or use statics "background"';
    }
    return `none (optional) — the background is learnt from the recording itself (τ = ${fixed(this.s.background_time_s, 3)} s)`;
  },
};
