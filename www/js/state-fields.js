// The strict readers of the page state's sections (state.js registerSection): each checks one
// value of a state object and throws an Error naming its path (`state.<section>.<field>: …`).
// The views use them in their sections' `check`.

import { $, clip, decimal, decimalIn, errorText } from './dom.js';
import { View } from './view.js';

/** True for a plain JSON object (not null, not an array). */
export const isObject = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

/** A value as an error names it (JSON, clipped). */
export const shown = (v) => clip(JSON.stringify(v) ?? String(v));

/** `v` must be an object with exactly the fields `keys`. */
export function fields(v, path, keys) {
  if (!isObject(v)) throw new Error(`${path}: ${shown(v)} is not an object (fields ${keys.join(', ')})`);
  for (const k of Object.keys(v)) {
    if (!keys.includes(k)) throw new Error(`${path}.${clip(k)}: unknown field (known: ${keys.join(', ')})`);
  }
  for (const k of keys) if (!(k in v)) throw new Error(`${path}.${k}: missing`);
}

/** A finite number (in `range`, dom.js decimalIn's form, if given). */
export function number(v, path, range = null) {
  if (typeof v !== 'number' || !Number.isFinite(v)) throw new Error(`${path}: ${shown(v)} is not a finite number`);
  if (range) decimalIn(String(v), path, range);
  return v;
}

/** true or false. */
export function flag(v, path) {
  if (typeof v !== 'boolean') throw new Error(`${path}: ${shown(v)} is not true or false`);
  return v;
}

/** One of <select> `id`'s values (a number is compared as written there). */
export function choice(v, path, id) {
  const values = [...$(id).options].map((o) => o.value);
  const t = typeof v === 'number' ? String(v) : v;
  if (typeof t !== 'string' || !values.includes(t)) {
    throw new Error(`${path}: ${shown(v)} is not one of ${values.map((x) => (x === '' ? '""' : x)).join(', ')}`);
  }
  return t;
}

/** [x0, x1, y0, y1] of finite numbers. */
export function rect(v, path) {
  if (!Array.isArray(v) || v.length !== 4) throw new Error(`${path}: ${shown(v)} is not [x0, x1, y0, y1]`);
  v.forEach((x, i) => number(x, `${path}[${i}]`));
  return v;
}

/** A window [x0, x1, y0, y1] that a zoom and pan of a view with home `home` could show (View.setWindow). */
export function checkWindow(v, path, home) {
  rect(v, path);
  const probe = new View(document.createElement('canvas'));
  probe.setHome(home);
  try {
    probe.setWindow(v);
  } catch (e) {
    throw new Error(`${path}: ${errorText(e)}`);
  }
}

/** The number in input `id`, or `fallback` where its text is not a valid one (being typed). */
export function inputNumber(id, fallback) {
  try {
    return decimal($(id).value, id);
  } catch (_) {
    return fallback;
  }
}
