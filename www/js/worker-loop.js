// The worker side of a replaceable job worker (see workers.js): the first message {type: 'init',
// module} instantiates the page's compiled wasm module; then jobs {type: 'job', gen, ...} are
// computed newest first (older jobs still waiting are dropped: a drag posts one per pointer
// move). Before each job the worker posts {type: 'start', gen}, so the page knows which job is
// running and since when (and may terminate the worker when that job went stale); after it
// {type: 'result', gen, ms, ...compute's object} or {type: 'error', gen, message}.

import init from '../pkg/scatterloc.js';
import { errorText } from './dom.js';

/**
 * Serves jobs with `compute(job)`, which returns {value, transfer?}: `value` (an object) is
 * merged into the result message, `transfer` lists its ArrayBuffers to move, not copy.
 */
export function serveLatest(compute) {
  let ready = null;
  let latest = null;
  let busy = false;
  const pause = () => new Promise((resolve) => setTimeout(resolve, 0)); // lets newer jobs in

  async function loop() {
    busy = true;
    try {
      await ready;
      while (latest) {
        const m = latest;
        latest = null;
        self.postMessage({ type: 'start', gen: m.gen });
        const t0 = performance.now();
        try {
          const { value, transfer = [] } = compute(m);
          self.postMessage({ type: 'result', gen: m.gen, ms: performance.now() - t0, ...value }, transfer);
        } catch (err) {
          self.postMessage({ type: 'error', gen: m.gen, message: errorText(err) });
        }
        await pause();
      }
    } finally {
      busy = false;
    }
  }

  self.onmessage = (e) => {
    const m = e.data;
    if (m.type === 'init') {
      ready = init({ module_or_path: m.module }).then(() => self.postMessage({ type: 'ready' }));
      return;
    }
    latest = m;
    if (!busy) loop();
  };
}
