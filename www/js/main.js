// The page's entry module (index.html loads only this): error capture first, so that a failure
// to fetch or run any other module still reaches the tests and the banner; then the page.

import { captureErrors, markFailed } from './hooks.js';
import { errorText, showError } from './dom.js';

captureErrors();
import('./app.js')
  .then((page) => page.start())
  .catch((e) => {
    const msg = errorText(e);
    try { showError(`The page could not start: ${msg}`); } catch (_) { /* banner missing */ }
    markFailed(msg);
    console.error(e);
  });
