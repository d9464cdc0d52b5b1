// The channel view's Replay (issue 40 §3; a part of the Channel class, channel.js): the opened
// recording fed frame by frame through the core's live run — the chain `scatterloc cir track
// --follow` runs, one state per frame as soon as the frame is tracked — at the frames' own
// times × a speed (1×, 2×, 5×, 10×, or as fast as possible), until its end or Stop. The map
// shows the states as they arrive (the segments growing, the current position and its 1σ
// ellipse, the links used), the read-out the frame, its time, event, segment and latency.
//
// Each frame's state is the JSON object the command line writes as its line (the core's one
// serialisation, LiveState::to_json, returned by the wasm ChannelReplay); the states at the
// end equal the batch run's (Run) wherever the live run has one (the live run reports a
// segment's states from its confirmation on; docs/recording.md "Streaming frames").
//
// The replay runs in a worker of its own (channel-worker.js, job 'replay', on workers.js'
// JobWorker), started for the replay and terminated at its end or at Stop: Stop is immediate,
// and the live run's memory goes with the worker. Latency per frame is measured on the page:
// from the time the frame was due (its time ÷ speed after the start; as fast as possible: when
// the worker took it) to the page receiving its state (performance.timeOrigin + now() on both
// sides), besides the live run's own time for the frame (push_ms, in the worker).

import { $, errorText, fixed } from './dom.js';
import { JobWorker } from './workers.js';
import { drawChannel } from './channel-draw.js';

/** The speeds offered (0: as fast as possible). */
export const REPLAY_SPEEDS = [1, 2, 5, 10, 0];

/** The median and the largest of a list of numbers ({median, max}; nulls when empty). */
function spread(xs) {
  if (!xs.length) return { median: null, max: null };
  const s = xs.slice().sort((a, b) => a - b);
  const m = s.length >> 1;
  return { median: s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2, max: s[s.length - 1] };
}

/** The Replay part of the Channel class (channel.js mixes it in). */
export const channelReplay = {
  /** The Replay button and its speed. */
  bindReplay() {
    this.replay = null; // {running, speed, frames, states, lines, runs, latencyMs, pushMs, ended, error, show, …}
    this.replays = 0;
    $('chan-replay').addEventListener('click', () => this.startReplay());
  },

  /** Replaying now. */
  replaying() { return !!(this.replay && this.replay.running); },

  /** Starts replaying the open recording with the panel's settings (a running one is stopped first). */
  async startReplay() {
    if (this.running || this.replaying()) return;
    if (!this.rec) {
      this.fail('Replay: open, drop or simulate a recording first');
      return;
    }
    let settings;
    try {
      settings = this.panelSettings();
    } catch (e) {
      this.fail(`Replay: ${errorText(e)}`);
      return;
    }
    this.pause();
    const speed = Number($('chan-replay-speed').value);
    const calibration = this.s.calibration === 'file' && this.cal ? this.cal.bytes : null;
    const rp = {
      running: true, speed, frames: this.rec.summary.snapshots, states: [], lines: [], runs: [],
      latencyMs: [], pushMs: [], ended: null, error: null, show: true, overlay: null,
      t0: performance.now(), wallMs: null, id: ++this.replays,
    };
    this.replay = rp;
    this.showButtons();
    this.showReplay();
    this.redraw();
    const module = await this.jobs.module;
    if (this.replay !== rp || !rp.running) return; // stopped meanwhile
    const worker = new JobWorker(new URL('./channel-worker.js', import.meta.url), module, {
      staleMs: Infinity,
      onProgress: (m) => this.onReplayFrame(rp, m),
      onResult: () => this.endReplay(rp, 'done'),
      onError: (message) => this.endReplay(rp, 'error', message),
    });
    rp.worker = worker;
    worker.post({
      kind: 'replay', scenario: this.ctx.app.scenario_json(), recording: this.rec.bytes, calibration,
      settings, speed,
    });
  },

  /** One frame's state from the worker: kept, shown on the map and in the read-out. */
  onReplayFrame(rp, m) {
    if (this.replay !== rp || !rp.running) return;
    const received = performance.timeOrigin + performance.now();
    const s = JSON.parse(m.line);
    rp.lines.push(m.line);
    rp.states.push(s);
    rp.frames = m.frames;
    rp.latencyMs.push(received - m.arrived_at);
    rp.pushMs.push(m.push_ms);
    if (s.state && s.segment !== null) {
      while (rp.runs.length <= s.segment) rp.runs.push([]);
      rp.runs[s.segment].push([s.state[0], s.state[1]]);
    }
    rp.overlay = {
      track_m: rp.runs, segment: s.state ? s.segment : null, state: s.state,
      sigma_ellipse: m.overlay ? m.overlay.sigma_ellipse : null, links: m.overlay ? m.overlay.links : [],
    };
    this.showReplay();
    if (this.active()) this.redraw();
  },

  /** Stops the replay (Stop): the worker is terminated at once; the states so far stay shown. */
  stopReplay() {
    if (this.replaying()) this.endReplay(this.replay, 'stopped');
  },

  /** The replay `rp` ended ('done', 'stopped' or 'error' with `message`): its worker goes. */
  endReplay(rp, how, message = null) {
    if (!rp.running) return;
    rp.running = false;
    rp.ended = how;
    rp.error = message;
    rp.wallMs = performance.now() - rp.t0;
    if (rp.worker) {
      rp.worker.cancel();
      if (rp.worker.worker) rp.worker.drop();
    }
    rp.worker = null;
    if (how === 'error') this.fail(`Replay: ${message}`);
    this.showButtons();
    this.showReplay();
    this.redraw();
  },

  /** Forgets the replay shown (a new recording, a new result): stopped first if running. */
  clearReplay() {
    this.stopReplay();
    this.replay = null;
    this.showReplay();
  },

  /** The map goes back to the result's cursor (a seek or Play after a replay). */
  hideReplay() {
    if (this.replay && !this.replay.running && this.replay.show) {
      this.replay.show = false;
      this.showReplay();
    }
  },

  /** The read-out line of the replay. */
  showReplay() {
    const el = $('chan-replay-info');
    const rp = this.replay;
    el.hidden = !rp || !rp.show;
    if (!rp) {
      el.textContent = '';
      return;
    }
    const n = rp.states.length;
    const s = n ? rp.states[n - 1] : null;
    const lat = n ? rp.latencyMs[n - 1] : null;
    const speed = rp.speed > 0 ? `${rp.speed}×` : 'as fast as possible';
    let text;
    if (!s) {
      text = `Replay (${speed}): starting…`;
    } else {
      const seg = s.segment === null ? '—' : String(s.segment + 1);
      text = `Replay ${speed} · frame ${s.snapshot + 1} / ${rp.frames} · t = ${fixed(s.t_s, 2)} s · ${s.event}`
        + `${s.end ? ` (${s.end})` : ''} · segment ${seg} · latency ${fixed(lat, 1)} ms`;
    }
    if (rp.ended === 'done' || rp.ended === 'stopped') {
      const l = spread(rp.latencyMs);
      text += ` · ${rp.ended === 'done' ? 'done' : 'stopped'}: ${n} frames in ${fixed(rp.wallMs / 1000, 2)} s, latency median ${fixed(l.median, 1)} ms, max ${fixed(l.max, 1)} ms`;
    } else if (rp.ended === 'error') {
      text += ' · failed';
    }
    el.textContent = text;
    Object.assign(el.dataset, { state: rp.running ? 'running' : rp.ended || '', frame: String(n) });
  },

  /** The map layer of the replay (overlayLayer calls it while the replay is shown). */
  drawReplay(ctx, view) {
    const rp = this.replay;
    const k = Math.max(0, rp.states.length - 1);
    const tr = this.truth ? this.truth.data.states : null;
    const truth = tr && tr.length === rp.frames ? tr.map((s) => (s ? [s[0], s[1]] : null)) : null;
    return drawChannel(ctx, view, {
      overlay: rp.overlay, truth, step: k, nodes: this.ctx.st.nodes, stale: false,
    });
  },

  /**
   * The replay for the tests and the console: {running, speed, frames, done, states (each
   * frame's object, as `cir track --follow` writes it), lines (their JSON texts), ended
   * ('done' | 'stopped' | 'error' | null), error, shown, wallMs, latencyMs {median, max},
   * pushMs {median, max}, events {searching, started, tracked, lost}, replays (started so far)},
   * or null before the first.
   */
  replayState() {
    const rp = this.replay;
    if (!rp) return null;
    const events = { searching: 0, started: 0, tracked: 0, lost: 0 };
    for (const s of rp.states) events[s.event] = (events[s.event] || 0) + 1;
    return {
      running: rp.running, speed: rp.speed, frames: rp.frames, done: rp.states.length,
      states: rp.states, lines: rp.lines.slice(), ended: rp.ended, error: rp.error, shown: rp.show,
      wallMs: rp.wallMs, latencyMs: spread(rp.latencyMs), pushMs: spread(rp.pushMs), events,
      replays: this.replays,
    };
  },
};
