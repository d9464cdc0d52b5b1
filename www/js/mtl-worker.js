// Multi-target worker (a module Web Worker, served by worker-loop.js): computes the view of a
// scene with the wasm core (an MtlSession, which keeps its cache between scenes) off the page's
// main thread. Jobs: {gen, scene (JSON text)}; results: {view}. The page terminates and replaces
// this worker when it is stuck on a stale scene (workers.js).

import { MtlSession } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

let session = null;

serveLatest((m) => {
  if (!session) session = new MtlSession();
  return { value: { view: session.view(m.scene) } };
});
