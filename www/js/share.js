// Sharing a view through the URL hash: the scenario travels as base64url text in the hash, either
// of the compact scenario JSON (`scenario=`) or, where the browser has CompressionStream, of its
// raw-deflated bytes (`z=`, about a third of the length). Decoding is strict and bounded: a bad
// character, a bad length, bytes that are not UTF-8, a corrupt deflate stream or more than
// MAX_BYTES of text are errors naming what was wrong (the caller prefixes the option's name);
// the JSON itself is judged by the core (App.set_scenario_json). Works offline: no library.

/** Largest scenario text a link may carry (bytes, after inflating). */
export const MAX_BYTES = 1 << 20;

const B64URL = /^[A-Za-z0-9_-]*$/;

/** Bytes -> base64url text without padding. */
export function toBase64url(bytes) {
  let bin = '';
  for (let i = 0; i < bytes.length; i += 0x8000) bin += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(bin).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

/** Base64url text (padding optional) -> bytes; a bad character or length throws, naming it. */
export function fromBase64url(text) {
  const t = text.replace(/=+$/, '');
  if (t === '') throw new Error('empty (base64url text expected)');
  if (!B64URL.test(t)) {
    const i = [...t].findIndex((ch) => !B64URL.test(ch));
    throw new Error(`not base64url: character ${JSON.stringify([...t][i])} at position ${i}`);
  }
  if (t.length % 4 === 1) throw new Error(`not base64url: a length of ${t.length} characters is impossible`);
  if ((t.length * 3) / 4 > MAX_BYTES) throw new Error(`longer than ${MAX_BYTES} bytes`);
  const bin = atob(t.replace(/-/g, '+').replace(/_/g, '/') + '='.repeat((4 - (t.length % 4)) % 4));
  return Uint8Array.from(bin, (c) => c.charCodeAt(0));
}

/** UTF-8 bytes -> text; invalid UTF-8 throws. */
function utf8(bytes) {
  try {
    return new TextDecoder('utf-8', { fatal: true }).decode(bytes);
  } catch (_) {
    throw new Error('not UTF-8 text');
  }
}

/** True where the browser can deflate (and so write `z=` links). */
export const canDeflate = () => typeof CompressionStream === 'function' && typeof DecompressionStream === 'function';

async function pipe(bytes, transform, limit) {
  const reader = new Blob([bytes]).stream().pipeThrough(transform).getReader();
  const chunks = [];
  let total = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    total += value.length;
    if (total > limit) {
      reader.cancel().catch(() => {});
      throw new Error(`inflates to more than ${limit} bytes`);
    }
    chunks.push(value);
  }
  const out = new Uint8Array(total);
  let at = 0;
  for (const c of chunks) {
    out.set(c, at);
    at += c.length;
  }
  return out;
}

/**
 * Scenario JSON text -> the hash option carrying it: `['z', deflated base64url]` when the browser
 * can deflate, else `['scenario', base64url]`. The JSON is made compact first (numbers keep
 * their shortest round-trip form, so positions come back bit for bit).
 */
export async function encodeScenario(json) {
  const bytes = new TextEncoder().encode(JSON.stringify(JSON.parse(json)));
  if (canDeflate()) {
    try {
      return ['z', toBase64url(await pipe(bytes, new CompressionStream('deflate-raw'), Infinity))];
    } catch (_) { /* fall back to plain text */ }
  }
  return ['scenario', toBase64url(bytes)];
}

/** The scenario text of hash option `key` ('scenario' or 'z') with value `value`; throws naming the problem. */
export async function decodeScenario(key, value) {
  const bytes = fromBase64url(value);
  if (key === 'scenario') return utf8(bytes);
  if (!canDeflate()) throw new Error('this browser cannot inflate (no DecompressionStream); use a scenario= link');
  let raw;
  try {
    raw = await pipe(bytes, new DecompressionStream('deflate-raw'), MAX_BYTES);
  } catch (e) {
    throw new Error(e && /inflates to more/.test(e.message) ? e.message : `not deflate data (${e && e.message ? e.message : e})`);
  }
  return utf8(raw);
}

/**
 * The error of a scenario too large for a link: `tooLarge` is set (app.js then offers the
 * scenario file instead) and the message gives the size and the cap.
 */
function tooLarge(what) {
  const e = new Error(`${what}; a link carries at most ${MAX_BYTES} bytes (1 MiB): save the scenario as a file and share that (Import opens it)`);
  e.tooLarge = true;
  return e;
}

/**
 * The page's URL with a hash reopening this view: `mode`, the map grid `res`, the snapshot
 * `target` ({x, y, seed}: `target=x,y&seed=s`), the `roi` ([x0, x1, y0, y1] m, or null) and the
 * `scenario` (JSON text; `z=` or `scenario=`, see encodeScenario). Numbers are written in their
 * shortest round-trip form, which the page's strict parser reads back exactly. What the page
 * writes it reads (issue 24): a scenario over MAX_BYTES of compact JSON, or whose link the
 * reader would refuse (decodeScenario, run here on the link's own text), throws `tooLarge`
 * instead of giving a link. `state` (JSON text, or null): the rest of the page state (state.js
 * linkState), carried as `zstate=` (deflated) or `state=` (base64url), read back by decodeState
 * and then judged whole by `checkState(text)` (state.js checkLink: every section's check, as the
 * opened page restores it), so no link is given for a state that would not restore.
 */
export async function viewLink({ mode, res, target, roi, window, scenario, state = null, checkState = null }) {
  const parts = [`mode=${mode}`];
  if (res) parts.push(`res=${res}`);
  if (window) parts.push(`view=${window.join(',')}`);
  if (target) parts.push(`target=${target.x},${target.y}`, `seed=${target.seed}`);
  if (roi) parts.push(`roi=${roi.join(',')}`);
  if (state !== null) {
    // The rest of the page state (state.js), before the scenario: `zstate=` (deflated) or `state=`.
    const size = new TextEncoder().encode(state).length;
    if (size > MAX_BYTES) throw tooLarge(`the page state is ${size} bytes of JSON`);
    const [k, v] = await encodeScenario(state);
    const key = k === 'z' ? 'zstate' : 'state';
    const back = await decodeState(key, v);
    if (back !== JSON.stringify(JSON.parse(state))) {
      throw new Error(`the ${key}= text does not read back as the page state`);
    }
    if (checkState) {
      try {
        checkState(back);
      } catch (e) {
        throw new Error(`the page state would not restore from the link (${e && e.message ? e.message : e})`);
      }
    }
    parts.push(`${key}=${v}`);
  }
  const compact = JSON.stringify(JSON.parse(scenario));
  const size = new TextEncoder().encode(compact).length;
  if (size > MAX_BYTES) throw tooLarge(`the scenario is ${size} bytes of JSON`);
  const [key, value] = await encodeScenario(compact);
  let back;
  try {
    back = await decodeScenario(key, value);
  } catch (e) {
    throw tooLarge(`the scenario's ${key}= text would be refused (${e && e.message ? e.message : e})`);
  }
  if (back !== compact) throw new Error(`the ${key}= text does not read back as the scenario`);
  parts.push(`${key}=${value}`);
  return `${location.origin}${location.pathname}#${parts.join('&')}`;
}

/** The page-state text of hash option `key` ('state' or 'zstate'): decoded as decodeScenario does. */
export function decodeState(key, value) {
  return decodeScenario(key === 'state' ? 'scenario' : 'z', value);
}
