// Numbers shown in the panel's inputs: rounded for display (a dragged node's x reads 19.975, not
// 19.9748164163447), while the state keeps the exact value. An input remembers the exact value
// and the text it shows; reading it back gives the exact value as long as the text is the one
// shown, so committing an untouched field (or a neighbour of an edited one, as x beside y) never
// moves anything. Only a changed text is parsed (strictly, dom.js decimal).

import { decimal } from './dom.js';

/**
 * `v` as short text: 3 decimals at most for |v| ≥ 1, 4 significant digits below (trailing zeros
 * dropped); integers and non-numbers unchanged.
 */
export function displayNumber(v) {
  if (typeof v !== 'number' || !Number.isFinite(v) || Number.isInteger(v)) return String(v);
  const t = Math.abs(v) >= 1 ? v.toFixed(3) : v.toPrecision(4);
  return String(Number(t));
}

/** Shows number `v` (or '' for null / undefined) in input `el`, remembering the exact value. */
export function showNumber(el, v) {
  if (v === null || v === undefined || v === '') {
    el.value = '';
    delete el.dataset.exact;
    delete el.dataset.shown;
    return;
  }
  const shown = displayNumber(v);
  el.value = shown;
  el.dataset.exact = String(v);
  el.dataset.shown = shown;
}

/**
 * The number in input `el`: the exact value behind the displayed text while the text is
 * unchanged, else the typed text, strictly parsed (an Error naming `field`).
 */
export function readNumber(el, field) {
  if (el.dataset.shown !== undefined && el.value.trim() === el.dataset.shown) return Number(el.dataset.exact);
  return decimal(el.value, field);
}
