// The channel view's settings in one place: their names, the command line's defaults (`cir
// estimate` / `cir track`), their ranges (the core's limits) and the one strict check of a
// settings object, shared by the panel (channel.js reads its inputs through it) and the state
// helpers (channelSettings / applyChannelSettings). Nothing here touches the DOM.

import { clip, decimal } from './dom.js';

/** The trackers of `cir track --filter`. */
export const CHANNEL_FILTERS = ['ekf', 'ukf', 'pf'];
/**
 * Where the empty area comes from: a recording of it ('file'; optional: without one the
 * background is learnt from the recording itself), or a time range of the recording.
 */
export const CALIBRATION_SOURCES = ['file', 'range'];
/** How static paths are kept from the tracker (the core's StaticMode: `cir … --statics`). */
export const CHANNEL_STATICS = ['background', 'clusters'];
/**
 * Which delays the tracker reads (the core's DelayReference, `--delay-reference`); 'auto' sends
 * none: the recording's own `synchronized` flag decides (absolute without one).
 */
export const DELAY_REFERENCES = ['auto', 'absolute', 'los'];
/** The playback speeds of the transport's <select>. */
export const CHANNEL_SPEEDS = [0.25, 0.5, 1, 2, 4];

/**
 * Every setting: [key, kind, default, check]. Numbers are checked with `range` {min, max,
 * integer, open: [lo open, hi open], allowed (text)}: the core's limits (EstimatorConfig::validate:
 * 0 < P_fa < 1, 1 … MAX_PATHS = 64 paths; PROCESS_NOISE: 0 < q ≤ 1e6 m²/s³; pf MAX_PARTICLES
 * = 1000000). Defaults are the command line's (cir.rs: q = 1, EXTENT_SIGMA_M = 0.2 m, EKF,
 * 1000 particles, seed 1; the estimator's 12 paths and P_fa = 10⁻³; the simulator's 1 s of
 * empty area at the start; the core's ChannelRequest: statics 'background', the delay
 * reference of the recording, a background time constant of 10 s within limits::
 * BACKGROUND_TIME_S = 1e-3 … 1e6 s).
 */
export const CHANNEL_FIELDS = [
  ['filter', 'choice', 'ekf', { values: CHANNEL_FILTERS }],
  ['particles', 'number', 1000, { min: 1, max: 1_000_000, integer: true, allowed: 'an integer 1 … 1000000' }],
  ['seed', 'number', 1, { min: 0, max: Number.MAX_SAFE_INTEGER, integer: true, allowed: 'an integer 0 … 9007199254740991' }],
  ['process_noise', 'number', 1, { min: 0, max: 1e6, open: [true, false], allowed: '0 < q ≤ 1000000 m²/s³' }],
  ['p_fa', 'number', 1e-3, { min: 0, max: 1, open: [true, true], allowed: '0 < P_fa < 1' }],
  ['max_paths', 'number', 12, { min: 1, max: 64, integer: true, allowed: 'an integer 1 … 64' }],
  ['extent_sigma_m', 'number', 0.2, { min: 0, max: 1000, allowed: '0 … 1000 m' }],
  ['statics', 'choice', 'background', { values: CHANNEL_STATICS }],
  ['delay_reference', 'choice', 'auto', { values: DELAY_REFERENCES }],
  ['background_time_s', 'number', 10, { min: 1e-3, max: 1e6, allowed: '0.001 … 1000000 s' }],
  ['calibration', 'choice', 'file', { values: CALIBRATION_SOURCES }],
  ['empty_from_s', 'number', 0, { min: 0, max: 1e9, allowed: '0 … 1000000000 s' }],
  ['empty_to_s', 'number', 1, { min: 0, max: 1e9, allowed: '0 … 1000000000 s' }],
  ['link', 'number', 0, { min: 0, max: 4096, integer: true, allowed: 'an integer 0 … 4096' }],
  ['step', 'number', 0, { min: 0, max: 100_000_000, integer: true, allowed: 'an integer 0 … 100000000' }],
  ['speed', 'choice', 1, { values: CHANNEL_SPEEDS }],
];

/** The defaults as a fresh settings object. */
export function defaultChannelSettings() {
  return Object.fromEntries(CHANNEL_FIELDS.map(([k, , d]) => [k, d]));
}

/** `v` (a number) against `range`; throws naming `field`. */
function checkNumber(field, v, range) {
  if (typeof v !== 'number' || !Number.isFinite(v)) {
    throw new Error(`channel setting ${field}: ${clip(JSON.stringify(v) ?? String(v))} is not a finite number (allowed ${range.allowed})`);
  }
  const [loOpen, hiOpen] = range.open || [false, false];
  const inside = (loOpen ? v > range.min : v >= range.min) && (hiOpen ? v < range.max : v <= range.max);
  if (range.integer && !Number.isInteger(v)) throw new Error(`channel setting ${field}: ${v} is not an integer (allowed ${range.allowed})`);
  if (!inside) throw new Error(`channel setting ${field}: ${v} is out of range (allowed ${range.allowed})`);
  return v;
}

/** The text of an input for setting `key` as a number, strictly parsed (dom.js) and range-checked. */
export function parseChannelField(key, text, label = key) {
  const f = CHANNEL_FIELDS.find((x) => x[0] === key);
  if (!f || f[1] !== 'number') throw new Error(`channel setting ${key}: not a number setting`);
  const v = decimal(text, label);
  try {
    return checkNumber(key, v, f[3]);
  } catch (e) {
    // Name the input as the panel shows it.
    throw new Error(e.message.replace(`channel setting ${key}`, label));
  }
}

/**
 * A settings object checked strictly: a plain object with exactly the keys of CHANNEL_FIELDS (a
 * missing key takes its default; an unknown key, a wrong type or a value out of range throws an
 * Error naming the key, the value and what is allowed), and the empty range ordered (from < to).
 * Returns a fresh object.
 */
export function checkChannelSettings(obj) {
  if (obj === null || typeof obj !== 'object' || Array.isArray(obj)) {
    throw new Error(`channel settings: ${clip(JSON.stringify(obj) ?? String(obj))} is not an object`);
  }
  const known = CHANNEL_FIELDS.map((f) => f[0]);
  const unknown = Object.keys(obj).find((k) => !known.includes(k));
  if (unknown !== undefined) throw new Error(`channel settings: unknown setting "${clip(unknown)}" (known: ${known.join(', ')})`);
  const out = {};
  for (const [key, kind, def, check] of CHANNEL_FIELDS) {
    const v = Object.hasOwn(obj, key) ? obj[key] : def;
    if (kind === 'choice') {
      if (!check.values.includes(v)) {
        throw new Error(`channel setting ${key}: ${clip(JSON.stringify(v) ?? String(v))} is not one of ${check.values.join(', ')}`);
      }
      out[key] = v;
    } else {
      out[key] = checkNumber(key, v, check);
    }
  }
  if (!(out.empty_to_s > out.empty_from_s)) {
    throw new Error(`channel setting empty_to_s: ${out.empty_to_s} s is not after empty_from_s (${out.empty_from_s} s)`);
  }
  return out;
}
