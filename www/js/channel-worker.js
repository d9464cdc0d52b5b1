// Channel-view worker (a module Web Worker, served by worker-loop.js; the page side is
// channel-job.js on workers.js' JobWorker): simulates recordings and runs the core's channel job
// (ChannelJob: read the files, estimate every link's statics and paths, track in segments, the
// delay figure) off the page's main thread, in SLICE_MS slices, so progress is reported and Stop
// drops the job at its next pause.
//
// Jobs (besides worker-loop.js' own {type, gen}):
//   {kind: 'run', scenario: text, recording: Uint8Array | ArrayBuffer (.npz bytes),
//    calibration: Uint8Array | ArrayBuffer | null (.npz; null: settings.calibration_range_s,
//    or without one a background learnt from the recording), truth: text | null, targets:
//    'one' | 'auto' (several people too: ChannelJob.set_targets; absent: one), settings:
//    object (the core's ChannelRequest, see src/edge/wasm/channel/job.rs)}
//   {kind: 'simulate', scenario: text, settings: object (the core's SimulationRequest)}
//   {kind: 'replay', scenario, recording, calibration, settings (as 'run'), speed: number (1×
//    = the frames' own times; 0: as fast as possible)}: the recording frame by frame through
//    the core's live run (ChannelReplay, the chain of `cir track --follow`), each frame at its
//    own time ÷ speed; the page runs it in a worker of its own (channel-replay.js).
// Progress (run only): {type: 'progress', gen, phase ('estimate' | 'track' | 'figure' |
//   'results': the texts being written), done, total}.
// Progress (replay: one per frame): {type: 'progress', gen, frame, frames, line (the frame's
//   state as JSON text: the line `cir track --follow` writes), overlay ({sigma_ellipse, links}),
//   push_ms (the live run's time for the frame), arrived_at (when the frame was due, ms since
//   the epoch: performance.timeOrigin + now(); the page measures its latency from it)}.
// Results:
//   run:      {type: 'result', gen, ms, kind: 'run', summary: object, timings: {parse_ms,
//              estimate_ms, track_ms, figure_ms}, estimates: text (EST.json),
//              track: text (TRACK.json), figure: text (the delay figure's data), errors: text
//              (the error view), people: text (ChannelJob.people_json) | null (one person)}
//   replay:   {type: 'result', gen, ms, kind: 'replay', frames}
//   simulate: {type: 'result', gen, ms, kind: 'simulate', recording: ArrayBuffer, calibration:
//              ArrayBuffer, truth: text, scene: text, summary: object} (the buffers are
//              transferred)
// Errors: {type: 'error', gen, message} with the core's named message (e.g. "cfr: wrong shape …",
//   "npz: … (a zip bomb?)", "recording: 300000000 bytes, at most …").

import { ChannelJob, ChannelReplay, simulate_channel } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

const SLICE_MS = 40; // work between progress reports and cancellation checks

/** The bytes of a posted file (a Uint8Array, an ArrayBuffer, or null). */
const bytesOf = (b) => (b === null || b === undefined ? undefined : b instanceof Uint8Array ? b : new Uint8Array(b));

async function run(m, { progress, pause }) {
  const job = new ChannelJob(m.scenario, bytesOf(m.recording), bytesOf(m.calibration),
    m.truth ?? undefined, JSON.stringify(m.settings ?? {}));
  try {
    const several = m.targets === 'auto';
    if (several) job.set_targets('auto');
    for (;;) {
      const p = job.step(SLICE_MS);
      if (p.finished) break;
      progress({ phase: p.phase, done: p.done, total: p.total });
      await pause(); // throws when superseded or stopped
    }
    // Writing the texts (the figure's is megabytes) takes a while: say so first.
    progress({ phase: 'results', done: 0, total: 1 });
    return {
      value: {
        kind: 'run',
        summary: job.summary(),
        timings: job.timings(),
        estimates: job.estimates_json(),
        track: job.track_json(),
        figure: job.figure_json(),
        errors: job.errors_json(),
        people: several ? job.people_json() : null,
      },
    };
  } finally {
    job.free();
  }
}

function simulate(m) {
  const sim = simulate_channel(m.scenario, JSON.stringify(m.settings ?? {}));
  try {
    const recording = sim.recording().buffer;
    const calibration = sim.calibration().buffer;
    return {
      value: {
        kind: 'simulate', recording, calibration, truth: sim.truth_json(), scene: sim.scene_json(),
        summary: JSON.parse(sim.summary_json()),
      },
      transfer: [recording, calibration],
    };
  } finally {
    sim.free();
  }
}

/** Resolves after `ms` milliseconds. */
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** Longest run of frames without a pause when replaying as fast as possible, ms. */
const FAST_SLICE_MS = 16;

async function replay(m, { progress, pause }) {
  const r = new ChannelReplay(m.scenario, bytesOf(m.recording), bytesOf(m.calibration),
    JSON.stringify(m.settings ?? {}));
  try {
    const t = r.t_s();
    const speed = Number(m.speed) > 0 ? Number(m.speed) : 0;
    const origin = performance.timeOrigin;
    const start = performance.now();
    let paused = start;
    for (let k = 0; k < t.length; k++) {
      let due = null;
      if (speed > 0) {
        due = start + ((t[k] - t[0]) * 1000) / speed;
        const wait = due - performance.now();
        if (wait > 0) await sleep(wait);
      }
      if (speed > 0 || performance.now() - paused >= FAST_SLICE_MS) {
        await pause(); // throws when stopped
        paused = performance.now();
      }
      const a = performance.now();
      const line = r.push(k);
      const overlay = r.overlay();
      const b = performance.now();
      progress({ frame: k, frames: t.length, line, overlay, push_ms: b - a, arrived_at: origin + (due ?? a) });
    }
    return { value: { kind: 'replay', frames: t.length } };
  } finally {
    r.free();
  }
}

serveLatest(async (m, ctx) => {
  if (m.kind === 'simulate') return simulate(m);
  if (m.kind === 'replay') return replay(m, ctx);
  return run(m, ctx);
});
