// The page's entry module (index.html loads only this): error capture first, so that a failure
// to fetch or run any other module still reaches the tests and the banner; then the page.

import { captureErrors, markFailed } from './hooks.js';
import { errorText, showError } from './dom.js';
import { initTheme } from './theme.js';

captureErrors();
initTheme();
import('./app.js')
  .then((page) => page.start())
  .catch((e) => {
    const msg = errorText(e);
    try { showError(`The page could not start: ${msg}`); } catch (_) { /* banner missing */ }
    const loading = document.getElementById('loading');
    if (loading) loading.textContent = 'The page could not start (see the message above).';
    markFailed(msg);
    console.error(e);
  });
