// The colour theme: dark or light, following the system's `prefers-color-scheme` until the top
// bar's toggle (#theme-toggle) picks one (remembered in localStorage). The theme is the
// `data-theme` attribute of <html>, which switches style.css's colour variables; the canvases
// read theirs from the same variables (draw.js applyThemeColors) and are redrawn. Printing uses
// the light theme (the print stylesheet in style.css; the canvases are redrawn light for it).

import { $ } from './dom.js';
import { applyThemeColors } from './draw.js';

const KEY = 'scatterloc.theme';
const system = () => matchMedia('(prefers-color-scheme: light)');

/** The theme chosen with the toggle ('dark' | 'light'), or null (follow the system). */
function stored() {
  try {
    const t = localStorage.getItem(KEY);
    return t === 'dark' || t === 'light' ? t : null;
  } catch (_) {
    return null; // storage blocked
  }
}

function store(t) {
  try {
    if (t) localStorage.setItem(KEY, t); else localStorage.removeItem(KEY);
  } catch (_) { /* storage blocked: the choice lasts for this page only */ }
}

/** The theme in effect now. */
const current = () => stored() ?? (system().matches ? 'light' : 'dark');

/** Sets <html data-theme> before the page draws (main.js), so nothing flashes in the wrong theme. */
export function initTheme() {
  document.documentElement.dataset.theme = current();
}

/**
 * Wires the toggle; `redraw(now)` redraws the canvases (now: synchronously, before printing).
 * Returns {get, set, colors} (the page's hook window.theme).
 */
export function attachTheme(redraw) {
  const button = $('theme-toggle');
  const show = (t, now = false) => {
    document.documentElement.dataset.theme = t;
    button.setAttribute('aria-pressed', String(t === 'light'));
    applyThemeColors();
    redraw(now);
  };
  const apply = () => show(current());
  button.addEventListener('click', () => {
    store(current() === 'light' ? 'dark' : 'light');
    apply();
  });
  system().addEventListener('change', () => { if (!stored()) apply(); });
  addEventListener('beforeprint', () => show('light', true));
  addEventListener('afterprint', () => apply());
  apply();
  return {
    get: current,
    set: (t) => {
      store(t === 'dark' || t === 'light' ? t : null);
      apply();
    },
    colors: () => {
      const css = getComputedStyle(document.documentElement);
      return Object.fromEntries(['--plot-bg', '--plot-text', '--bg', '--text'].map((n) => [n, css.getPropertyValue(n).trim()]));
    },
  };
}
