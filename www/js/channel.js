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
// ([S] Fig. 4) and the error over time, each with the time cursor; over the error chart the
// segments are marked (the gaps shaded, each loss with its reason: channel-draw.js
// drawSegments); the map shows the segments up to the cursor, the iso-delay ellipses of the
// delays used, the links used and the filter's 1σ (channel-draw.js); with "People: several"
// it shows every labelled track of the recording (as `cir track --targets auto`) with its label
// and 1σ ellipse instead (people-draw.js). Files are read with
// File.arrayBuffer() and go to the worker only: nothing leaves the machine.
//
// The Channel class is composed of its parts: channel-files.js (the files and the settings
// panel), channel-run.js (the running job, the status line, stale marking) and channel-player.js
// (the cursor, the map layer, the charts, Save) and channel-replay.js (Replay: the recording
// frame by frame through the core's live run, as `cir track --follow`); this file holds its fields, the mode switch,
// the test hooks and the page state's `channel` section.
//
// The state section (registerChannelState) calls channelSettings() / applyChannelSettings(obj)
// (every setting, not the recording), checkChannelState(obj) before applying, and leaves CHANNEL_TRANSIENT (the cursor's
// snapshot, the playback speed) out of the undo history.

import { $, errorText } from './dom.js';
import { ChannelJobs } from './channel-job.js';
import { channelFields, checkChannelSettings, defaultChannelSettings } from './channel-settings.js';
import { registerSection } from './state.js';
import { channelFiles } from './channel-files.js';
import { channelRun } from './channel-run.js';
import { channelPlayer } from './channel-player.js';
import { channelReplay } from './channel-replay.js';

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

/**
 * The channel view: its fields here, its methods from channel-files.js, channel-run.js and
 * channel-player.js (mixed into the prototype below).
 */
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

  /** Every listener of the view: its files and settings, the job's buttons, the player. */
  bind() {
    this.bindFiles();
    this.bindRun();
    this.bindPlayer();
    this.bindReplay();
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
      replay: this.replayState(),
      people: this.peopleState(),
    };
  }

  /**
   * The several people of the result shown (null without): {labels (the labelled tracks' labels),
   * scans, layer (what the map drew last: {step, truth, tracks: [{label, colour, state, ellipse,
   * points, box}]})}; the document itself is texts().people.
   */
  peopleState() {
    const p = this.result && this.result.people;
    if (!p) return null;
    return { labels: p.track.tracks.map((t) => t.label), scans: p.track.t_s.length, layer: this.peopleLayer || null };
  }

  /**
   * The result's texts (TRACK.json, EST.json, the figure and error views, and the people
   * document of a run with several people, else null) for the tests, or null.
   */
  texts() {
    return this.result ? { ...this.result.texts } : null;
  }
}

// The parts' methods (each file's concern) on the one class, so the view is one object for app.js and the hooks.
Object.assign(Channel.prototype, channelFiles, channelRun, channelPlayer, channelReplay);
/** The panel's inputs from this.s (channel-files.js), and the People select (one or several). */
/** The settings' keys (for the state helper's documentation and tests; after the wasm start). */
export function channelSettingKeys() {
  return channelFields().map((f) => f[0]);
}

/**
 * Registers the page state's `channel` section: every setting of the channel view (not its
 * recordings). Optional (a state without it leaves the view as it is); the cursor's snapshot and
 * the playback speed are transient (CHANNEL_TRANSIENT).
 */
export function registerChannelState() {
  registerSection('channel', {
    get: channelSettings, apply: applyChannelSettings, check: checkChannelState, optional: true,
    transient: CHANNEL_TRANSIENT,
  });
}
