// The page's views, one list (VIEWS), and the page state's `mode` section (which view is shown).

import { registerSection } from './state.js';
import { shown } from './state-fields.js';

/**
 * The page's views: each has its top-bar button `mode-<view>`, is a value of the URL option
 * `mode` (app.js) and of the page state's `mode`, and has its entry in Help's Views.
 */
export const VIEWS = ['snapshot', 'tracking', 'mtl', 'channel'];

/**
 * Registers the state's `mode` section: the view shown (one of VIEWS; not in the undo history).
 * @param {object} st - the page's state object (app.js; `st.mode`)
 * @param {function} setMode - app.js setMode(view)
 */
export function registerModeState(st, setMode) {
  registerSection('mode', {
    history: false,
    get: () => st.mode,
    check: (v) => {
      if (!VIEWS.includes(v)) throw new Error(`state.mode: ${shown(v)} is not one of ${VIEWS.join(', ')}`);
    },
    apply: (v) => setMode(v),
  });
}
