// Channel-view worker (a module Web Worker, served by worker-loop.js; the page side is
// channel-job.js on workers.js' JobWorker): simulates recordings and runs the core's channel job
// (ChannelJob: read the files, estimate every link's statics and paths, track in segments, the
// delay figure) off the page's main thread, in SLICE_MS slices, so progress is reported and Stop
// drops the job at its next pause.
//
// Jobs (besides worker-loop.js' own {type, gen}):
//   {kind: 'run', scenario: text, recording: Uint8Array | ArrayBuffer (.npz bytes),
//    calibration: Uint8Array | ArrayBuffer | null (.npz; null: settings.calibration_range_s,
//    or without one a background learnt from the recording), truth: text | null, settings:
//    object (the core's ChannelRequest, see src/edge/wasm/channel/job.rs)}
//   {kind: 'simulate', scenario: text, settings: object (the core's SimulationRequest)}
// Progress (run only): {type: 'progress', gen, phase ('estimate' | 'track' | 'figure' |
//   'results': the texts being written), done, total}.
// Results:
//   run:      {type: 'result', gen, ms, kind: 'run', summary: object, timings: {parse_ms,
//              estimate_ms, track_ms, figure_ms}, estimates: text (EST.json),
//              track: text (TRACK.json), figure: text (the delay figure's data), errors: text
//              (the error view)}
//   simulate: {type: 'result', gen, ms, kind: 'simulate', recording: ArrayBuffer, calibration:
//              ArrayBuffer, truth: text, scene: text, summary: object} (the buffers are
//              transferred)
// Errors: {type: 'error', gen, message} with the core's named message (e.g. "cfr: wrong shape …",
//   "npz: … (a zip bomb?)", "recording: 300000000 bytes, at most …").

import { ChannelJob, simulate_channel } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

const SLICE_MS = 40; // work between progress reports and cancellation checks

/** The bytes of a posted file (a Uint8Array, an ArrayBuffer, or null). */
const bytesOf = (b) => (b === null || b === undefined ? undefined : b instanceof Uint8Array ? b : new Uint8Array(b));

async function run(m, { progress, pause }) {
  const job = new ChannelJob(m.scenario, bytesOf(m.recording), bytesOf(m.calibration),
    m.truth ?? undefined, JSON.stringify(m.settings ?? {}));
  try {
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

serveLatest(async (m, ctx) => (m.kind === 'simulate' ? simulate(m) : run(m, ctx)));
