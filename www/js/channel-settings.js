// The channel view's settings in one place: their names, defaults and ranges, and the one strict
// check of a settings object, shared by the panel (channel.js reads its inputs through it) and
// the state helpers (channelSettings / applyChannelSettings). The settings of the core's
// ChannelRequest (the tracker's and the front end's: `cir estimate` / `cir track`) come with
// their defaults and ranges from the core's table (wasm channel_settings, read once after
// app.js has initialised the module): a new setting or a new default is written in the core
// only. The page's own settings (where the empty area comes from, the link shown, the cursor,
// the playback speed, one person or several) are listed here. Nothing here touches the DOM.

import { clip, decimal } from './dom.js';
import { channel_settings } from '../pkg/scatterloc.js';

/**
 * Where the empty area comes from: a recording of it ('file'; optional: without one the
 * background is learnt from the recording itself), or a time range of the recording.
 */
export const CALIBRATION_SOURCES = ['file', 'range'];
/**
 * How many people a run tracks: 'one' (the single-target track, `cir track`) or 'several'
 * (also the labelled tracks of `cir track --targets auto`, drawn on the map instead).
 */
export const CHANNEL_TARGETS = ['one', 'several'];
/** The playback speeds of the transport's <select>. */
export const CHANNEL_SPEEDS = [0.25, 0.5, 1, 2, 4];

/** The page's keys of the core's settings where they differ from the request's JSON keys. */
const PAGE_KEYS = { pfa: 'p_fa' };
/**
 * The page's choice for a core choice whose default is none ('auto': no delay_reference is
 * sent, the recording's own `synchronized` flag decides, absolute without one).
 */
const AUTO = 'auto';

/** The page's own settings (the same shape as channelFields'). */
const PAGE_FIELDS = [
  ['targets', 'choice', 'one', { values: CHANNEL_TARGETS }],
  ['calibration', 'choice', 'file', { values: CALIBRATION_SOURCES }],
  ['empty_from_s', 'number', 0, { min: 0, max: 1e9, allowed: '0 … 1000000000 s' }],
  ['empty_to_s', 'number', 1, { min: 0, max: 1e9, allowed: '0 … 1000000000 s' }],
  ['link', 'number', 0, { min: 0, max: 4096, integer: true, allowed: 'an integer 0 … 4096' }],
  ['step', 'number', 0, { min: 0, max: 100_000_000, integer: true, allowed: 'an integer 0 … 100000000' }],
  ['speed', 'choice', 1, { values: CHANNEL_SPEEDS }],
];

/** A range in the page's words: `an integer 1 … 64`, `0 … 1000 m`, `0 < q ≤ 1000000 m²/s³`. */
function allowedText({ min, max, integer, open }, unit, symbol) {
  if (integer) return `an integer ${min} … ${max}`;
  const u = unit ? ` ${unit}` : '';
  // No upper end (the core's largest finite number): `σ_floor ≥ 0 m/s`.
  if (max === Number.MAX_VALUE && !open[1]) return `${symbol} ${open[0] ? '>' : '≥'} ${min}${u}`;
  if (!open[0] && !open[1]) return `${min} … ${max}${u}`;
  return `${min} ${open[0] ? '<' : '≤'} ${symbol} ${open[1] ? '<' : '≤'} ${max}${u}`;
}

/**
 * One entry of the core's table ({key, kind: 'number' | 'integer' | 'choice', default, min, max,
 * open, unit, symbol | values}) as a page field. Integers stop at Number.MAX_SAFE_INTEGER (the
 * largest the page holds exactly: the particle filter's seed).
 */
function coreField(e) {
  const key = PAGE_KEYS[e.key] ?? e.key;
  if (e.kind === 'choice') {
    return e.default === null
      ? [key, 'choice', AUTO, { values: [AUTO, ...e.values] }]
      : [key, 'choice', e.default, { values: e.values }];
  }
  const integer = e.kind === 'integer';
  // A number whose default is none takes its lower end (cpi_snapshots: 1, no CPI).
  const def = e.default ?? e.min;
  const range = { min: e.min, max: integer ? Math.min(e.max, Number.MAX_SAFE_INTEGER) : e.max, integer, open: e.open };
  range.allowed = allowedText(range, e.unit, e.symbol);
  return [key, 'number', def, range];
}

let fields = null;

/**
 * Every setting: [key, kind ('number' | 'choice'), default, check]. Numbers are checked with
 * `check` {min, max, integer, open: [lo open, hi open], allowed (text)}, choices with {values}.
 * The core's settings first (filter, particles, seed, process_noise, p_fa, max_paths,
 * extent_sigma_m, statics, delay_reference, background_time_s, cpi_snapshots, range_rate_floor_mps:
 * the core's order), then the
 * page's (PAGE_FIELDS).
 */
export function channelFields() {
  if (!fields) fields = [...JSON.parse(channel_settings()).map(coreField), ...PAGE_FIELDS];
  return fields;
}

/** The defaults as a fresh settings object. */
export function defaultChannelSettings() {
  return Object.fromEntries(channelFields().map(([k, , d]) => [k, d]));
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
  const f = channelFields().find((x) => x[0] === key);
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
 * A settings object checked strictly: a plain object with exactly the keys of channelFields() (a
 * missing key takes its default; an unknown key, a wrong type or a value out of range throws an
 * Error naming the key, the value and what is allowed), and the empty range ordered (from < to).
 * Returns a fresh object.
 */
export function checkChannelSettings(obj) {
  if (obj === null || typeof obj !== 'object' || Array.isArray(obj)) {
    throw new Error(`channel settings: ${clip(JSON.stringify(obj) ?? String(obj))} is not an object`);
  }
  const known = channelFields().map((f) => f[0]);
  const unknown = Object.keys(obj).find((k) => !known.includes(k));
  if (unknown !== undefined) throw new Error(`channel settings: unknown setting "${clip(unknown)}" (known: ${known.join(', ')})`);
  const out = {};
  for (const [key, kind, def, check] of channelFields()) {
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
