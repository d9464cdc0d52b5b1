// "Lock colours": a fixed colour range for the CRLB map (the snapshot and tracking views), so two
// layouts can be compared by colour. Unlocked, the scale spans the map's finite values (it
// follows every drag, zoom, grid change and Optimize); locked, it stays at [min, max] m (log
// scale) and cells outside it take the end colours, marked ≤ / ≥ at the ends of the colour bar.
// The canvas map, the colour bar, the exported SVG (option `scale`) and the read-out use it. The
// colouring itself is the core's (render_map_rgba_locked); this file holds the state and controls.
//
// For the state / undo helper: getColourRange() -> {locked, min_m, max_m} and
// setColourRange({locked, min_m, max_m}) (strict; throws a ColourRangeError naming the field).

import { $, decimal, errorText, showError, clearError } from './dom.js';
import { registerSection } from './state.js';

/** The error of a bad colour range (its `name` is 'ColourRangeError'). */
export class ColourRangeError extends Error {
  constructor(message) {
    super(message);
    this.name = 'ColourRangeError';
  }
}

/** Digits a range taken from the map is rounded to for the inputs. */
const DISPLAY_DIGITS = 3;

/**
 * A colour range checked: {locked: boolean, min_m, max_m} with finite 0 < min_m < max_m (m); when
 * unlocked, min_m and max_m may be null (no range entered). Returns a clean copy or throws.
 */
export function checkColourRange(obj) {
  if (!obj || typeof obj !== 'object' || Array.isArray(obj)) {
    throw new ColourRangeError('colour range: an object {locked, min_m, max_m} is required');
  }
  const extra = Object.keys(obj).filter((k) => !['locked', 'min_m', 'max_m'].includes(k));
  if (extra.length) throw new ColourRangeError(`colour range: unknown field ${extra[0]}`);
  if (typeof obj.locked !== 'boolean') throw new ColourRangeError('colour range: locked must be true or false');
  const { min_m: min, max_m: max } = obj;
  if (!obj.locked && (min ?? null) === null && (max ?? null) === null) return { locked: false, min_m: null, max_m: null };
  for (const [field, v] of [['min_m', min], ['max_m', max]]) {
    if (typeof v !== 'number' || !Number.isFinite(v)) throw new ColourRangeError(`colour range: ${field} must be a finite number of metres`);
    if (!(v > 0)) throw new ColourRangeError(`colour range: ${field} = ${v} must be above 0 m`);
  }
  if (!(min < max)) throw new ColourRangeError(`colour range: min_m = ${min} must be below max_m = ${max}`);
  return { locked: obj.locked, min_m: min, max_m: max };
}

export class ColourLock {
  /** @param {object} ctx - {wasm, st, changed} (app.js); `repaint()` recolours the map. */
  constructor(ctx, repaint) {
    this.ctx = ctx;
    this.repaint = repaint;
    this.range = { locked: false, min_m: null, max_m: null };
    $('colour-lock').addEventListener('change', () => this.fromInputs(true));
    for (const id of ['colour-min', 'colour-max']) {
      const el = $(id);
      el.setAttribute('inputmode', 'decimal');
      el.setAttribute('autocomplete', 'off');
      el.setAttribute('spellcheck', 'false');
      el.addEventListener('change', () => this.fromInputs(false));
    }
    this.show();
  }

  /** {locked, min_m, max_m} (min_m / max_m null when none was entered). */
  get() {
    return { ...this.range };
  }

  /** Sets the range (checkColourRange: throws ColourRangeError, changing nothing). */
  set(obj) {
    this.range = checkColourRange(obj);
    this.show();
    this.repaint();
  }

  /** The locked scale [min, max] m, or null when unlocked. */
  scale() {
    return this.range.locked ? [this.range.min_m, this.range.max_m] : null;
  }

  /**
   * The inputs' state into the range. Locking with empty inputs takes the map's current range
   * (rounded for display). A bad entry names the field and keeps the last good range.
   */
  fromInputs(toggled) {
    const { st } = this.ctx;
    const locked = $('colour-lock').checked;
    if (toggled && locked && ($('colour-min').value.trim() === '' || $('colour-max').value.trim() === '')) {
      const [min, max] = st.range || [];
      if (!(min > 0 && max > min && Number.isFinite(max))) {
        $('colour-lock').checked = false;
        showError('Lock colours: the map has no bounded cells to take a range from; enter min and max');
        return;
      }
      $('colour-min').value = String(Number(min.toPrecision(DISPLAY_DIGITS)));
      $('colour-max').value = String(Number(max.toPrecision(DISPLAY_DIGITS)));
    }
    try {
      const read = (id, field) => ($(id).value.trim() === '' && !locked ? null : decimal($(id).value, field));
      const min = read('colour-min', 'colour range min (m)');
      const max = read('colour-max', 'colour range max (m)');
      this.range = checkColourRange({ locked, min_m: min, max_m: max });
      clearError();
    } catch (e) {
      showError(`Lock colours: ${errorText(e)}`);
      this.show();
      return;
    }
    this.show();
    this.repaint();
  }

  /** The controls from the range. */
  show() {
    const r = this.range;
    $('colour-lock').checked = r.locked;
    $('colour-lock').closest('.colour-lock').dataset.locked = String(r.locked);
    const fmt = (v) => (v === null ? '' : String(v));
    if (document.activeElement !== $('colour-min')) $('colour-min').value = fmt(r.min_m);
    if (document.activeElement !== $('colour-max')) $('colour-max').value = fmt(r.max_m);
  }

  /**
   * Colours `values` into `rgba` (the core): on the locked range, or on the map's own. Returns
   * {range: [min, max], clamped: [below, above]} (cells drawn in the end colours).
   */
  render(values, rgba) {
    const { wasm } = this.ctx;
    const s = this.scale();
    if (!s) return { range: Array.from(wasm.render_map_rgba(values, rgba)), clamped: [0, 0] };
    const r = Array.from(wasm.render_map_rgba_locked(values, rgba, s[0], s[1]));
    return { range: [r[0], r[1]], clamped: [r[2], r[3]] };
  }

  /** A note for the read-out of a bound `v` (m) outside the locked range, else ''. */
  note(v) {
    const s = this.scale();
    if (!s || !(Number.isFinite(v) && v > 0)) return '';
    if (v < s[0]) return '  ·  below the locked colour range (drawn in its lowest colour)';
    if (v > s[1]) return '  ·  above the locked colour range (drawn in its highest colour)';
    return '';
  }
}

/**
 * Registers the page state's `colours` section: the colour lock's range (optional: a state
 * without it leaves the lock as it is).
 * @param {ColourLock} lock - the map's colour lock (map.js `lock`)
 */
export function registerColoursState(lock) {
  registerSection('colours', { get: () => lock.get(), apply: (v) => lock.set(v), optional: true });
}
