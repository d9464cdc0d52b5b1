// The page's DOM helpers, in one place: element lookup, number parsing of inputs, key/value
// read-outs, the error banner and canvas sizing. Nothing here runs at import time, so a worker
// may import it too (for errorText).

/** The element with this id. */
export const $ = (id) => document.getElementById(id);

/** Text -> number; empty text is NaN, so the core names the field instead of taking 0. */
export function num(text) {
  const t = String(text).trim();
  return t === '' ? NaN : Number(t);
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
