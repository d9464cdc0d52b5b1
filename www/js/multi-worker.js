// Several-people worker (a module Web Worker, served by worker-loop.js): runs the core's
// track_people (simulate the walkers, track them with the PMB tracker or the GNN baseline, score
// the track's GOSPA) off the page's main thread (multi.js). Jobs: {gen, scenario (JSON text),
// walkers, paths? (drawn paths, [[x0, y0, x1, y1], …] m), method, seed}. One synchronous wasm call: a newer job or a cancel terminates the worker
// (workers.js staleMs 0). The result: {gen, ms, text (the document's JSON text)}.

import { track_people } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

serveLatest((m) => ({
  value: { text: track_people(m.scenario, JSON.stringify({ walkers: m.walkers, paths: m.paths, method: m.method, seed: m.seed })) },
}));
