// The page's DOM helpers, in one place: element lookup, strict number parsing of inputs and the
// URL, null-safe number formatting, key/value read-outs, the error banner and canvas sizing.
// Nothing here runs at import time, so a worker may import it too (for errorText).

/** The element with this id. */
export const $ = (id) => document.getElementById(id);

/** A plain decimal number: optional sign (`-`, `+` or `−`), digits with an optional point, optional exponent. */
const DECIMAL = /^[+\-\u2212]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;

/** Text for a message: at most 64 characters (longer text ends in "…"), so a huge input cannot flood the banner. */
export function clip(text) {
  const t = String(text);
  return t.length > 64 ? `${t.slice(0, 63)}…` : t;
}

/**
 * Text -> number by strict decimal parsing (the one parser of every number the page reads from
 * an input or the URL): hex (`0x10`), `Infinity`, empty text and trailing junk are rejected with
 * an Error naming `field`, e.g. `radio.bandwidth_hz: "0x10" is not a decimal number`.
 */
export function decimal(text, field) {
  const t = String(text ?? '').trim();
  if (t === '') throw new Error(`${field}: empty (a decimal number is required)`);
  if (!DECIMAL.test(t)) throw new Error(`${field}: "${clip(t)}" is not a decimal number`);
  const v = Number(t.replace('\u2212', '-'));
  if (!Number.isFinite(v)) throw new Error(`${field}: "${clip(t)}" is out of range (not a finite number)`);
  return v;
}

/**
 * Strict decimal parse plus a range check: a number in [min, max] (an integer when `integer`),
 * else an Error naming `field`, the value and the allowed range (`unit` appended to it).
 */
export function decimalIn(text, field, { min, max, integer = false, unit = '' }) {
  const v = decimal(text, field);
  const allowed = `allowed ${integer ? 'an integer ' : ''}${fmtBound(min)} … ${fmtBound(max)}${unit ? ` ${unit}` : ''}`;
  if (integer && !Number.isInteger(v)) throw new Error(`${field}: ${clip(String(text).trim())} is not an integer (${allowed})`);
  if (!(v >= min && v <= max)) throw new Error(`${field}: ${clip(String(text).trim())} is out of range (${allowed})`);
  return v;
}

const fmtBound = (v) => (Number.isInteger(v) ? String(v) : String(v).replace('-', '−'));

/**
 * A number with `digits` decimals for display, safe for whatever the core sends: null,
 * undefined or NaN -> "—", ±Infinity -> "∞" / "−∞" (the core serialises non-finite numbers as
 * null). Use this instead of `toFixed` everywhere in the page.
 */
export function fixed(v, digits) {
  if (v === null || v === undefined || typeof v !== 'number' || Number.isNaN(v)) return '—';
  if (v === Infinity) return '∞';
  if (v === -Infinity) return '−∞';
  return v.toFixed(digits);
}

/** An exception (or anything thrown or rejected) as message text. */
export function errorText(e) {
  return e && e.message ? e.message : String(e);
}

/** Replaces the children of a <dl> with [label, value, cssClass] rows. */
export function fillKeyValues(dl, rows) {
  dl.replaceChildren();
  for (const [k, v, cls] of rows) {
    const dt = document.createElement('dt');
    dt.textContent = k;
    const dd = document.createElement('dd');
    dd.textContent = v;
    if (cls) dd.className = cls;
    dl.append(dt, dd);
  }
}

/** Shows the error banner with `message`. */
export function showError(message) {
  $('error-text').textContent = message;
  $('error').hidden = false;
}

/** Hides and empties the error banner. */
export function clearError() {
  $('error').hidden = true;
  $('error-text').textContent = '';
}

/**
 * Matches a canvas' backing store to its CSS size times the device pixel ratio (touching it only
 * when the size changed, since that clears it). Returns {width, height} (CSS px, at least 1) and dpr.
 */
export function fitCanvas(canvas) {
  const r = canvas.getBoundingClientRect();
  const dpr = window.devicePixelRatio || 1;
  const width = Math.max(1, r.width);
  const height = Math.max(1, r.height);
  const w = Math.round(width * dpr);
  const h = Math.round(height * dpr);
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  return { width, height, dpr };
}
