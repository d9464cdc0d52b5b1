// CRLB map worker (a module Web Worker, served by worker-loop.js): the full-resolution map when
// it costs more than a frame on the main thread (map.js). Jobs: {gen, scenario (JSON text), n,
// window ([x0, x1, y0, y1] m, the view's), doppler (null, or doppler.js job()'s {cpi,
// velocity_mps}: the maps with Doppler)}; results: {n, window, values (Float64Array, n·n,
// transferred; with Doppler the position bound), velocity (with Doppler: the velocity bound,
// m/s, transferred; else absent), kernelMs (the core's kernel time)}.

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
  const grid = { window: m.window, nx: m.n, ny: m.n };
  if (m.doppler) {
    const velocity = new Float64Array(m.n * m.n);
    const kernelMs = app.compute_doppler_maps_in(JSON.stringify({ ...grid, ...m.doppler }), values, velocity);
    return { value: { n: m.n, window: m.window, values, velocity, kernelMs }, transfer: [values.buffer, velocity.buffer] };
  }
  const kernelMs = app.compute_map_in(JSON.stringify(grid), values);
  return { value: { n: m.n, window: m.window, values, kernelMs }, transfer: [values.buffer] };
});
