// Drawing only: every number drawn here (map colours, ticks, labels, ellipses) comes from the
// wasm core; this file places it on the canvas through the view transform.

import { Zoom } from './view.js';

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
  iso: 'rgba(255,255,255,0.62)',
  baseline: 'rgba(255,255,255,0.28)',
};
export const LINK_COLORS = ['#f4f4f0', '#ffd166', '#9be564', '#ff8fab', '#b8c0ff', '#7ee8fa', '#ffb86b', '#d0a2f7'];
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

export function cross(ctx, p, r, color, width) {
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.beginPath();
  ctx.moveTo(p.x - r, p.y - r); ctx.lineTo(p.x + r, p.y + r);
  ctx.moveTo(p.x - r, p.y + r); ctx.lineTo(p.x + r, p.y - r);
  ctx.stroke();
}

export function haloText(ctx, text, x, y) {
  ctx.lineWidth = 3;
  ctx.strokeStyle = 'rgba(10,12,18,0.85)';
  ctx.strokeText(text, x, y);
  ctx.fillText(text, x, y);
}

/** The heatmap: the wasm-coloured RGBA image (row 0 = lowest y), flipped to y-up. */
function drawMap(ctx, view, st) {
  const r = view.rect;
  if (!st.mapCanvas) return;
  ctx.save();
  ctx.imageSmoothingEnabled = true;
  ctx.imageSmoothingQuality = 'high';
  ctx.translate(r.x, r.y + r.h);
  ctx.scale(1, -1);
  ctx.drawImage(st.mapCanvas, 0, 0, r.w, r.h);
  ctx.restore();
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

function drawColorbar(ctx, view, st, w) {
  const r = view.rect;
  const bx = r.x + r.w + 18;
  const bw = 14;
  ctx.save();
  ctx.imageSmoothingEnabled = true;
  ctx.translate(bx, r.y + r.h);
  ctx.scale(1, -1);
  ctx.drawImage(st.barCanvas, 0, 0, bw, r.h);
  ctx.restore();
  ctx.strokeStyle = C.frame;
  ctx.lineWidth = 1;
  ctx.strokeRect(bx + 0.5, r.y + 0.5, bw, r.h);
  ctx.font = FONT;
  ctx.fillStyle = C.text;
  ctx.textAlign = 'left';
  ctx.textBaseline = 'middle';
  const [min, max] = st.range || [Infinity, Infinity];
  for (const t of w.colorbar_ticks(min, max)) {
    const y = r.y + r.h - t.frac * r.h;
    ctx.beginPath(); ctx.moveTo(bx + bw, y); ctx.lineTo(bx + bw + 5, y); ctx.stroke();
    ctx.fillText(t.label, bx + bw + 8, y);
  }
  // Unbounded swatch under the bar.
  ctx.fillStyle = st.unboundedColor;
  ctx.fillRect(bx, r.y + r.h + 10, bw, 10);
  ctx.strokeRect(bx + 0.5, r.y + r.h + 10.5, bw, 10);
  ctx.fillStyle = C.muted;
  ctx.fillText('unbounded', bx + bw + 8, r.y + r.h + 15);
}

function drawNetwork(ctx, view, st) {
  const n = st.nodes;
  ctx.setLineDash([4, 4]);
  ctx.strokeStyle = C.baseline;
  ctx.lineWidth = 1;
  ctx.beginPath();
  for (const [k, l] of n.links) {
    const a = view.toPixel(n.transmitters[k].x, n.transmitters[k].y);
    const b = view.toPixel(n.receivers[l].x, n.receivers[l].y);
    ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y);
  }
  ctx.stroke();
  ctx.setLineDash([]);
  ctx.font = FONT_B;
  ctx.textAlign = 'left';
  ctx.textBaseline = 'bottom';
  n.receivers.forEach((rx, i) => {
    rxMarker(ctx, view.toPixel(rx.x, rx.y), rx.name, st.selected.kind === 'rx' && st.selected.index === i);
  });
  n.transmitters.forEach((tx, i) => {
    const p = view.toPixel(tx.x, tx.y);
    if (tx.boresight) {
      ctx.strokeStyle = C.tx; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(p.x, p.y);
      ctx.lineTo(p.x + 26 * tx.boresight[0], p.y - 26 * tx.boresight[1]); ctx.stroke();
    }
    txMarker(ctx, p, tx.name, st.selected.kind === 'tx' && st.selected.index === i);
  });
}

/** A selection ring of radius `r` px around pixel `p`. */
export function ring(ctx, p, r) {
  ctx.beginPath(); ctx.arc(p.x, p.y, r, 0, FULL);
  ctx.lineWidth = 2; ctx.strokeStyle = C.sel; ctx.stroke();
}

/** A receiver marker (disc) at pixel `p` with its label above right; ringed when `selected`. */
export function rxMarker(ctx, p, label, selected) {
  if (selected) ring(ctx, p, 11);
  ctx.beginPath(); ctx.arc(p.x, p.y, 6, 0, FULL);
  ctx.fillStyle = C.rx; ctx.fill();
  ctx.lineWidth = 2; ctx.strokeStyle = '#1b1f27'; ctx.stroke();
  ctx.fillStyle = C.rx;
  ctx.textBaseline = 'bottom';
  haloText(ctx, label, p.x + 9, p.y - 5);
}

/** A transmitter marker (triangle) at pixel `p` with its label below right; ringed when `selected`. */
export function txMarker(ctx, p, label, selected) {
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

/** Iso-delay ellipses and markers of the simulated snapshot in the main view. */
function drawTargetMain(ctx, view, fix) {
  const r = view.rect;
  ctx.save();
  ctx.beginPath(); ctx.rect(r.x, r.y, r.w, r.h); ctx.clip();
  ctx.lineWidth = 1;
  fix.links.forEach((l, i) => {
    if (l.outline.length < 3) return;
    ctx.strokeStyle = LINK_COLORS[i % LINK_COLORS.length];
    ctx.globalAlpha = 0.7;
    polyline(ctx, view, l.outline, true);
    ctx.stroke();
  });
  ctx.globalAlpha = 1;
  ctx.restore();
  const t = view.toPixel(fix.truth.x, fix.truth.y);
  cross(ctx, t, 6, '#0d1017', 4);
  cross(ctx, t, 6, '#ffffff', 2);
  if (fix.fix) {
    const f = view.toPixel(fix.fix.x, fix.fix.y);
    ctx.beginPath(); ctx.arc(f.x, f.y, 9, 0, FULL);
    ctx.strokeStyle = C.fix; ctx.lineWidth = 1.5; ctx.stroke();
  }
}

/**
 * Zoom inset around the target: iso-delay ellipses, CRLB and LM (or EKF) 1σ ellipses, scale bar.
 * `title` names it; inside the plot it keeps off the `avoid` points ([[x, y, weight?], …] m) if it can.
 */
function drawInset(ctx, view, fix, w, title, avoid) {
  const r = view.rect;
  const t = view.toPixel(fix.truth.x, fix.truth.y);
  const pad = 10;
  // Outside the plot when a wide area leaves room above or below it, else in a plot corner.
  const below = view.height - (r.y + r.h) - 52;
  const above = r.y - 4;
  let size;
  let box;
  if (below >= 170) {
    size = Math.min(270, below - pad);
    box = { x: r.x + r.w - size, y: r.y + r.h + 52 };
  } else if (above >= 170) {
    size = Math.min(270, above - pad);
    box = { x: r.x + r.w - size, y: r.y - size - pad };
  } else {
    size = Math.min(250, r.w * 0.42, r.h * 0.55);
    if (size < 80) return;
    const corners = [
      { x: r.x + r.w - size - pad, y: r.y + pad },
      { x: r.x + pad, y: r.y + pad },
      { x: r.x + r.w - size - pad, y: r.y + r.h - size - pad },
      { x: r.x + pad, y: r.y + r.h - size - pad },
    ];
    // The corner whose box keeps clear of the target marker and covers the least weight of the
    // `avoid` points ([x, y, weight = 1], m; e.g. a track), the first in this order on ties.
    const inside = (c, p, m) => p.x > c.x - m && p.x < c.x + size + m && p.y > c.y - m && p.y < c.y + size + m;
    const cost = (c) => avoid.reduce((sum, [x, y, wt = 1]) => sum + (inside(c, view.toPixel(x, y), 6) ? wt : 0),
      inside(c, t, 12) ? 1e9 : 0);
    box = corners.reduce((best, c) => (cost(c) < cost(best) ? c : best));
  }
  const z = new Zoom(box.x, box.y, size, fix.truth, fix.view_radius_m);
  // Leader line from the target to the inset.
  ctx.strokeStyle = 'rgba(255,255,255,0.45)';
  ctx.lineWidth = 1;
  ctx.setLineDash([3, 3]);
  ctx.beginPath(); ctx.moveTo(t.x, t.y);
  ctx.lineTo(box.x + size / 2, box.y + (t.y < box.y ? 0 : size)); ctx.stroke();
  ctx.setLineDash([]);
  ctx.save();
  ctx.shadowColor = 'rgba(0,0,0,0.5)'; ctx.shadowBlur = 12;
  ctx.fillStyle = 'rgba(13,16,23,0.94)';
  ctx.fillRect(box.x, box.y, size, size);
  ctx.restore();
  ctx.save();
  ctx.beginPath(); ctx.rect(box.x, box.y, size, size); ctx.clip();
  ctx.lineWidth = 1.25;
  // The core hands over only the arc near the target, so no path is millions of pixels wide.
  fix.links.forEach((l, i) => {
    if (l.arc.length < 2) return;
    ctx.strokeStyle = LINK_COLORS[i % LINK_COLORS.length];
    ctx.globalAlpha = 0.85;
    polyline(ctx, z, l.arc, false);
    ctx.stroke();
  });
  ctx.globalAlpha = 1;
  const c = z.toPixel(fix.truth.x, fix.truth.y);
  if (fix.crlb.ellipse) {
    ctx.setLineDash([5, 4]); ctx.lineWidth = 2; ctx.strokeStyle = C.crlb;
    ellipsePath(ctx, z, fix.crlb.ellipse); ctx.stroke();
    ctx.setLineDash([]);
  }
  if (fix.fix) {
    const f = z.toPixel(fix.fix.x, fix.fix.y);
    if (fix.fix.ellipse) {
      ctx.lineWidth = 2; ctx.strokeStyle = C.fix;
      ellipsePath(ctx, z, fix.fix.ellipse); ctx.stroke();
      ctx.fillStyle = 'rgba(255,169,77,0.12)'; ctx.fill();
    }
    ctx.beginPath(); ctx.arc(f.x, f.y, 3.5, 0, FULL); ctx.fillStyle = C.fix; ctx.fill();
  }
  cross(ctx, c, 5, '#ffffff', 2);
  // Scale bar.
  const bar = w.scale_bar(fix.view_radius_m * 0.8);
  if (bar) {
    const len = z.len(bar.length_m);
    const y = box.y + size - 14;
    ctx.strokeStyle = '#fff'; ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(box.x + 12, y - 4); ctx.lineTo(box.x + 12, y); ctx.lineTo(box.x + 12 + len, y); ctx.lineTo(box.x + 12 + len, y - 4);
    ctx.stroke();
    ctx.font = FONT; ctx.fillStyle = '#fff'; ctx.textAlign = 'left'; ctx.textBaseline = 'bottom';
    haloText(ctx, bar.label, box.x + 16 + len, y + 4);
  }
  ctx.font = FONT_B; ctx.fillStyle = C.text; ctx.textAlign = 'left'; ctx.textBaseline = 'top';
  haloText(ctx, title, box.x + 8, box.y + 7);
  ctx.restore();
  ctx.strokeStyle = C.frame; ctx.lineWidth = 1;
  ctx.strokeRect(box.x + 0.5, box.y + 0.5, size, size);
}

/**
 * Redraws the whole canvas from the state: `st.fix` is a snapshot (or a snapshot-shaped track
 * frame), `st.overlay(ctx, view)` draws extra layers under the markers, `st.insetTitle` names
 * the zoom inset and `st.insetAvoid` lists points it should not cover.
 */
export function drawScene(view, st, w) {
  const ctx = view.context();
  ctx.fillStyle = C.bg;
  ctx.fillRect(0, 0, view.width, view.height);
  drawMap(ctx, view, st);
  drawAxes(ctx, view, w);
  drawColorbar(ctx, view, st, w);
  if (st.overlay) st.overlay(ctx, view);
  if (st.fix) drawTargetMain(ctx, view, st.fix);
  drawNetwork(ctx, view, st);
  if (st.fix) drawInset(ctx, view, st.fix, w, st.insetTitle || 'target zoom', st.insetAvoid || []);
}

/** A 1-pixel-wide canvas holding the colour bar gradient (dark first = bottom). */
export function makeBarCanvas(rgba) {
  const n = rgba.length / 4;
  const c = document.createElement('canvas');
  c.width = 1;
  c.height = n;
  const img = new ImageData(new Uint8ClampedArray(rgba), 1, n);
  c.getContext('2d').putImageData(img, 0, 0);
  return c;
}
