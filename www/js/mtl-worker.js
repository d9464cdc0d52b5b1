// Multi-target worker (a module Web Worker): computes the view of a scene with the wasm core
// (an MtlSession, which keeps its cache between scenes) off the page's main thread. Messages in: {gen, scene (JSON text)}; only the newest
// scene waiting is computed (a drag posts one per pointer move). Messages out: {type: 'view', gen,
// view, ms} (ms = this worker's time for the call), {type: 'error', gen, message} and, once the
// wasm module is compiled, {type: 'ready'}.

import init, { MtlSession } from '../pkg/scatterloc.js';
import { errorText } from './dom.js';

let session = null;
const ready = init().then(() => {
  session = new MtlSession();
  self.postMessage({ type: 'ready' });
});
let latest = null;
let busy = false;

self.onmessage = (e) => {
  latest = e.data;
  if (!busy) loop();
};

/** Lets queued messages (newer scenes) in. */
const pause = () => new Promise((resolve) => setTimeout(resolve, 0));

async function loop() {
  busy = true;
  try {
    await ready;
    while (latest) {
      const m = latest;
      latest = null;
      const t0 = performance.now();
      try {
        const view = session.view(m.scene);
        self.postMessage({ type: 'view', gen: m.gen, view, ms: performance.now() - t0 });
      } catch (err) {
        self.postMessage({ type: 'error', gen: m.gen, message: errorText(err) });
      }
      await pause();
    }
  } finally {
    busy = false;
  }
}
