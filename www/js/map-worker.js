// CRLB map worker (a module Web Worker, served by worker-loop.js): the full-resolution map when
// it costs more than a frame on the main thread (map.js). Jobs: {gen, scenario (JSON text), n,
// window ([x0, x1, y0, y1] m, the view's)}; results: {n, window, values (Float64Array, n·n,
// transferred), kernelMs (the core's kernel time)}.

import { App } from '../pkg/scatterloc.js';
import { serveLatest } from './worker-loop.js';

let app = null;
let scenario = null;

serveLatest((m) => {
  if (m.scenario !== scenario) {
    const next = new App(m.scenario);
    if (app) app.free();
    app = next;
    scenario = m.scenario;
  }
  const values = new Float64Array(m.n * m.n);
  const kernelMs = app.compute_map_in(JSON.stringify({ window: m.window, nx: m.n, ny: m.n }), values);
  return { value: { n: m.n, window: m.window, values, kernelMs }, transfer: [values.buffer] };
});
