// Canvas drawing shared by the views (map, tracking, multi-target): colours, fonts, paths
// through a transform (View or Zoom), markers, axes. Every number drawn comes from the wasm core;
// this file only places it on the canvas.

export const C = {
  bg: '#141922',
  frame: '#3a4456',
  text: '#c9d2e0',
  muted: '#8a94a6',
  grid: 'rgba(255,255,255,0.10)',
  tx: '#ff6b6b',
  rx: '#f4f4f0',
  fix: '#ffa94d',
  crlb: '#5cc8ff',
  sel: '#5cc8ff',
  focus: '#ffd166',
  iso: 'rgba(255,255,255,0.62)',
  baseline: 'rgba(255,255,255,0.28)',
  // The dark casing under the main map's iso-delay ellipses, so a yellow or green link reads on
  // the map's yellow-green end too (map.js drawTargetMain; the same in both themes).
  mapCasing: 'rgba(10,12,18,0.85)',
  // The multi-target view's colours (mtl-draw.js), per theme, the same CSS variables as its legend
  // (#legend-mtl): see applyThemeColors.
  halo: 'rgba(10,12,18,0.85)',
  casing: 'transparent',
  marker: '#ffffff',
  regionEdge: 'rgba(92,200,255,0.6)',
  discFill: 'rgba(150,160,178,0.55)',
  discEdge: '#c9d2e0',
  blocked: '#ff4d4f',
  los: 'rgba(255,255,255,0.35)',
  seed: 'rgba(200,210,225,0.8)',
  hyp: '#ffd166',
  hypRej: 'rgba(160,170,185,0.8)',
  fa: '#ff8fb0',
  det: '#ffa94d',
  // The zoom inset's own colours (map.js drawInset), per theme: see applyThemeColors.
  insetBg: '#0d1017',
  insetText: '#c9d2e0',
  insetHalo: 'rgba(10,12,18,0.85)',
  insetTruth: '#ffffff',
  insetCasing: 'transparent',
  insetCrlb: '#5cc8ff',
  insetFix: '#ffa94d',
  insetFixFill: 'rgba(255,169,77,0.25)',
};
/** The links' colours, from the core (present::LINK_RGB, as the figures'): set by setLinkColors. */
let LINK_COLORS = ['#ffffff'];
/** Takes the links' colours from the core's flat `[r, g, b, …]` (wasm link_rgb); app.js at start. */
export function setLinkColors(rgb) {
  LINK_COLORS = [];
  for (let i = 0; i + 2 < rgb.length; i += 3) LINK_COLORS.push(`rgb(${rgb[i]},${rgb[i + 1]},${rgb[i + 2]})`);
}
/** The plot colour of link (or TRP) `i`. */
export const linkColor = (i) => LINK_COLORS[i % LINK_COLORS.length];
export const FONT = '11.5px system-ui, -apple-system, "Segoe UI", Roboto, sans-serif';
export const FONT_B = '600 11.5px system-ui, -apple-system, "Segoe UI", Roboto, sans-serif';
export const FULL = 2 * Math.PI;

/**
 * Ellipse {cx, cy, a, b, angle} through a transform (View or Zoom); y flips the angle's sign.
 * `magnify` enlarges it on screen only (a labelled exaggeration).
 */
export function ellipsePath(ctx, tr, e, magnify = 1) {
  const c = tr.toPixel(e.cx, e.cy);
  ctx.beginPath();
  ctx.ellipse(c.x, c.y, tr.len(e.a) * magnify, tr.len(e.b) * magnify, -e.angle, 0, FULL);
}

/** A path through points [[x, y], …] (m) via a transform. */
export function polyline(ctx, tr, points, closed) {
  ctx.beginPath();
  points.forEach(([x, y], k) => {
    const q = tr.toPixel(x, y);
    if (k === 0) ctx.moveTo(q.x, q.y); else ctx.lineTo(q.x, q.y);
  });
  if (closed) ctx.closePath();
}

/** Saves the context and clips it to the rectangle `r` {x, y, w, h} (CSS px); undo with ctx.restore(). */
export function clipTo(ctx, r) {
  ctx.save();
  ctx.beginPath(); ctx.rect(r.x, r.y, r.w, r.h); ctx.clip();
}

export function cross(ctx, p, r, color, width) {
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.beginPath();
  ctx.moveTo(p.x - r, p.y - r); ctx.lineTo(p.x + r, p.y + r);
  ctx.moveTo(p.x - r, p.y + r); ctx.lineTo(p.x + r, p.y - r);
  ctx.stroke();
}

/** `text` at (x, y) in the current fill over a 3 px halo (dark by default; the inset passes its theme's). */
export function haloText(ctx, text, x, y, halo = 'rgba(10,12,18,0.85)') {
  ctx.lineWidth = 3;
  ctx.strokeStyle = halo;
  ctx.strokeText(text, x, y);
  ctx.fillText(text, x, y);
}

/**
 * `text` cut at the end with '…' so that it is at most `maxW` px wide in the context's font
 * (`text` itself when it fits).
 */
export function fitText(ctx, text, maxW) {
  if (ctx.measureText(text).width <= maxW) return text;
  let n = text.length;
  while (n > 0 && ctx.measureText(`${text.slice(0, n).trimEnd()}…`).width > maxW) n--;
  return `${text.slice(0, n).trimEnd()}…`;
}

/** True if boxes `a` and `b` ({x, y, w, h}) overlap. */
export function boxesOverlap(a, b) {
  return a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;
}

/**
 * Draws `text` (the context's font and fill, with haloText's halo) at the first of `spots`
 * ([dx, dy, textAlign, textBaseline] from the anchor pixel `p`) whose box lies inside `rect` and
 * overlaps none of the boxes `taken`; failing that, at the first spot moved up or down by whole
 * label heights that does; failing that, at the first spot moved inside `rect`. Returns the box
 * drawn {x, y, w, h} (CSS px, halo included) and adds it to `taken`. `haloColor`: haloText's.
 */
export function placeLabel(ctx, text, p, rect, taken, spots, haloColor = undefined) {
  const halo = 1.5;
  const boxAt = ([dx, dy, align, baseline], shift = 0) => {
    ctx.textAlign = align;
    ctx.textBaseline = baseline;
    const m = ctx.measureText(text);
    const x = p.x + dx;
    const y = p.y + dy + shift;
    return {
      x: x - m.actualBoundingBoxLeft - halo, y: y - m.actualBoundingBoxAscent - halo,
      w: m.actualBoundingBoxLeft + m.actualBoundingBoxRight + 2 * halo,
      h: m.actualBoundingBoxAscent + m.actualBoundingBoxDescent + 2 * halo,
      at: { x, y, align, baseline },
    };
  };
  const inside = (b) => b.x >= rect.x && b.y >= rect.y && b.x + b.w <= rect.x + rect.w && b.y + b.h <= rect.y + rect.h;
  const free = (b) => inside(b) && !taken.some((t) => boxesOverlap(b, t));
  let best = spots.map((s) => boxAt(s)).find(free);
  if (!best) {
    const step = boxAt(spots[0]).h + 1;
    for (let k = 1; k <= 8 && !best; k++) {
      for (const sign of [1, -1]) {
        best = spots.map((s) => boxAt(s, sign * k * step)).find(free);
        if (best) break;
      }
    }
  }
  if (!best) {
    const b = boxAt(spots[0]);
    const dx = Math.min(Math.max(b.x, rect.x), rect.x + rect.w - b.w) - b.x;
    const dy = Math.min(Math.max(b.y, rect.y), rect.y + rect.h - b.h) - b.y;
    best = { ...b, x: b.x + dx, y: b.y + dy, at: { ...b.at, x: b.at.x + dx, y: b.at.y + dy } };
  }
  ctx.textAlign = best.at.align;
  ctx.textBaseline = best.at.baseline;
  haloText(ctx, text, best.at.x, best.at.y, haloColor);
  const box = { x: best.x, y: best.y, w: best.w, h: best.h };
  taken.push(box);
  return box;
}

/** Grid, tick labels (from the core's `axis_ticks`), axis titles and the frame of the plot rectangle. */
export function drawAxes(ctx, view, w) {
  const r = view.rect;
  const [x0, x1, y0, y1] = view.area;
  ctx.font = FONT;
  ctx.fillStyle = C.text;
  ctx.strokeStyle = C.grid;
  ctx.lineWidth = 1;
  const xt = w.axis_ticks(x0, x1, Math.max(2, Math.floor(r.w / 70)));
  const yt = w.axis_ticks(y0, y1, Math.max(2, Math.floor(r.h / 50)));
  view.drawn.ticks = { x: xt.map((t) => t.value), y: yt.map((t) => t.value) };
  ctx.beginPath();
  for (const t of xt) {
    const p = view.toPixel(t.value, y0);
    ctx.moveTo(Math.round(p.x) + 0.5, r.y); ctx.lineTo(Math.round(p.x) + 0.5, r.y + r.h + 5);
  }
  for (const t of yt) {
    const p = view.toPixel(x0, t.value);
    ctx.moveTo(r.x - 5, Math.round(p.y) + 0.5); ctx.lineTo(r.x + r.w, Math.round(p.y) + 0.5);
  }
  ctx.stroke();
  ctx.textAlign = 'center';
  ctx.textBaseline = 'top';
  for (const t of xt) ctx.fillText(t.label, view.toPixel(t.value, y0).x, r.y + r.h + 8);
  ctx.textAlign = 'right';
  ctx.textBaseline = 'middle';
  for (const t of yt) ctx.fillText(t.label, r.x - 8, view.toPixel(x0, t.value).y);
  ctx.fillStyle = C.muted;
  ctx.textAlign = 'center';
  ctx.textBaseline = 'alphabetic';
  ctx.fillText('x (m)', r.x + r.w / 2, r.y + r.h + 36);
  ctx.save();
  ctx.translate(r.x - 42, r.y + r.h / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.fillText('y (m)', 0, 0);
  ctx.restore();
  ctx.strokeStyle = C.frame;
  ctx.strokeRect(Math.round(r.x) + 0.5, Math.round(r.y) + 0.5, Math.round(r.w), Math.round(r.h));
}

/**
 * A scale bar in the plot's lower-left corner: the core's round length (scale_bar) no longer than
 * a fifth of the window's width, so it follows the zoom.
 */
export function drawScaleBar(ctx, view, w) {
  const r = view.rect;
  const bar = w.scale_bar((view.area[1] - view.area[0]) / 5);
  view.drawn.scaleBar = bar ? { length_m: bar.length_m, label: bar.label } : null;
  if (!bar) return;
  const len = view.len(bar.length_m);
  const x = r.x + 10;
  const y = r.y + r.h - 10;
  for (const [color, width] of [['rgba(0,0,0,0.7)', 4], ['#fff', 2]]) {
    ctx.strokeStyle = color; ctx.lineWidth = width;
    ctx.beginPath();
    ctx.moveTo(x, y - 5); ctx.lineTo(x, y); ctx.lineTo(x + len, y); ctx.lineTo(x + len, y - 5);
    ctx.stroke();
  }
  ctx.font = FONT; ctx.fillStyle = '#fff'; ctx.textAlign = 'left'; ctx.textBaseline = 'bottom';
  haloText(ctx, bar.label, x + len + 5, y + 4);
}

/** The plot has keyboard focus (keyboard.js): the selected object also gets a focus ring. */
export const plotFocus = { on: false };

/** The keyboard focus ring of radius `r` px around pixel `p` (bright over a dark halo). */
export function focusRing(ctx, p, r) {
  ctx.beginPath(); ctx.arc(p.x, p.y, r, 0, FULL);
  ctx.lineWidth = 5; ctx.strokeStyle = 'rgba(10,12,18,0.9)'; ctx.stroke();
  ctx.lineWidth = 2.5; ctx.strokeStyle = C.focus; ctx.stroke();
}

/** A selection ring of radius `r` px around pixel `p` (and the focus ring while focused). */
export function ring(ctx, p, r) {
  ctx.beginPath(); ctx.arc(p.x, p.y, r, 0, FULL);
  ctx.lineWidth = 2; ctx.strokeStyle = C.sel; ctx.stroke();
  if (plotFocus.on) focusRing(ctx, p, r + 4);
}

/** A receiver marker (disc) at pixel `p` with its label above right; ringed when `selected`. */
function rxMarker(ctx, p, label, selected) {
  if (selected) ring(ctx, p, 11);
  ctx.beginPath(); ctx.arc(p.x, p.y, 6, 0, FULL);
  ctx.fillStyle = C.rx; ctx.fill();
  ctx.lineWidth = 2; ctx.strokeStyle = '#1b1f27'; ctx.stroke();
  ctx.fillStyle = C.rx;
  ctx.textBaseline = 'bottom';
  haloText(ctx, label, p.x + 9, p.y - 5);
}

/** A transmitter marker (triangle) at pixel `p` with its label below right; ringed when `selected`. */
function txMarker(ctx, p, label, selected) {
  if (selected) ring(ctx, p, 12);
  ctx.beginPath();
  ctx.moveTo(p.x, p.y - 9); ctx.lineTo(p.x + 8, p.y + 6); ctx.lineTo(p.x - 8, p.y + 6); ctx.closePath();
  ctx.fillStyle = C.tx; ctx.fill();
  ctx.lineWidth = 1.5; ctx.strokeStyle = '#1b1f27'; ctx.stroke();
  ctx.fillStyle = C.tx;
  ctx.textBaseline = 'top';
  haloText(ctx, label, p.x + 9, p.y + 5);
  ctx.textBaseline = 'bottom';
}

/** True if `sel` ({kind, index} or null) is object `index` of `kind`. */
export function isSelected(sel, kind, index) {
  return !!sel && sel.kind === kind && sel.index === index;
}

/**
 * Receiver discs, then transmitter triangles (with a boresight tick where a node has one), each
 * labelled; nodes are {x, y, name, boresight?} (m); `sel` {kind: 'rx' | 'tx', index} is ringed.
 */
export function drawNodes(ctx, view, receivers, transmitters, sel) {
  ctx.font = FONT_B;
  ctx.textAlign = 'left';
  receivers.forEach((n, i) => rxMarker(ctx, view.toPixel(n.x, n.y), n.name, isSelected(sel, 'rx', i)));
  transmitters.forEach((n, i) => {
    const p = view.toPixel(n.x, n.y);
    if (n.boresight) {
      ctx.strokeStyle = C.tx; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(p.x, p.y);
      ctx.lineTo(p.x + 26 * n.boresight[0], p.y - 26 * n.boresight[1]); ctx.stroke();
    }
    txMarker(ctx, p, n.name, isSelected(sel, 'tx', i));
  });
}

/**
 * The canvas colours of the theme (theme.js): the plot's background, frame, axis text, muted
 * text and grid from the CSS variables --plot-bg, --plot-frame, --plot-text, --plot-muted and
 * --plot-grid (style.css, per theme) into C; the multi-target view's label halo, link casing
 * and markers from --plot-halo, --plot-casing and the variables its legend's symbols use; the
 * zoom inset's background, text, halo, truth
 * cross and link casing from --inset-*, its CRLB and fix from the page's --crlb, --fix and
 * --ekf-fill. The map, its overlays and the markers keep their colours in both themes (they are
 * drawn over the map's dark-to-bright scale).
 */
export function applyThemeColors() {
  const css = getComputedStyle(document.documentElement);
  for (const [key, name] of [['bg', '--plot-bg'], ['frame', '--plot-frame'], ['text', '--plot-text'],
    ['muted', '--plot-muted'], ['grid', '--plot-grid'], ['insetBg', '--inset-bg'], ['insetText', '--inset-text'],
    ['insetHalo', '--inset-halo'], ['insetTruth', '--inset-truth'], ['insetCasing', '--inset-casing'],
    ['insetCrlb', '--crlb'], ['insetFix', '--fix'], ['insetFixFill', '--ekf-fill'],
    ['halo', '--plot-halo'], ['casing', '--plot-casing'], ['marker', '--marker'], ['regionEdge', '--region-edge'],
    ['discFill', '--disc-fill'], ['discEdge', '--disc-edge'], ['blocked', '--blocked'], ['los', '--los'],
    ['seed', '--seed'], ['hyp', '--hyp'], ['hypRej', '--hyp-rej'], ['fa', '--fa'], ['det', '--fix']]) {
    const v = css.getPropertyValue(name).trim();
    if (v) C[key] = v;
  }
}
