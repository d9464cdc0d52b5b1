// Drawing of a simulated track over the CRLB map (all numbers from the wasm core's Track): the
// truth path, the filter's track (EKF, UKF or PF) with its 1σ covariance ellipses (magnified by a labelled factor), and
// the arrow of a drawn trajectory (and the arrows of the several-people view's drawn paths). The current step's markers, iso-delay ellipses and the zoom
// inset are drawn by draw.js from the snapshot-shaped frame.

import { C, FONT_B, FULL, clipTo, ellipsePath, placeLabel, polyline } from './draw.js';

const TRUTH = 'rgba(255,255,255,0.9)';
const EKF = C.fix;
const ARROW = '#7ee8fa';

/** A dark line under a path, so it reads on every map colour. */
function halo(ctx, view, points, width) {
  ctx.strokeStyle = 'rgba(10,12,18,0.55)';
  ctx.lineWidth = width;
  polyline(ctx, view, points, false);
  ctx.stroke();
}

/** An arrow from a to b (CSS px) with a head of `size` px. */
function arrow(ctx, a, b, size) {
  const ang = Math.atan2(b.y - a.y, b.x - a.x);
  ctx.beginPath();
  ctx.moveTo(a.x, a.y);
  ctx.lineTo(b.x, b.y);
  ctx.stroke();
  ctx.beginPath();
  ctx.moveTo(b.x, b.y);
  ctx.lineTo(b.x - size * Math.cos(ang - 0.45), b.y - size * Math.sin(ang - 0.45));
  ctx.lineTo(b.x - size * Math.cos(ang + 0.45), b.y - size * Math.sin(ang + 0.45));
  ctx.closePath();
  ctx.fill();
}

/**
 * The drawn trajectory's prior mean: start ring and arrow to the point reached at the end, its
 * label kept inside the plot (placeLabel). Returns the label's box {x, y, w, h} (CSS px) or null.
 */
function drawArrow(ctx, view, d) {
  const a = view.toPixel(d.x0, d.y0);
  const b = view.toPixel(d.x1, d.y1);
  ctx.strokeStyle = ARROW;
  ctx.fillStyle = ARROW;
  ctx.lineWidth = 2;
  ctx.setLineDash([]);
  arrow(ctx, a, b, 11);
  ctx.beginPath(); ctx.arc(a.x, a.y, 5, 0, FULL); ctx.stroke();
  if (!d.label) return null;
  ctx.font = FONT_B;
  // Above right of the arrow's head, else where it fits inside the plot.
  return placeLabel(ctx, d.label, b, view.rect, [], [[8, -6, 'left', 'bottom'], [-8, -6, 'right', 'bottom'],
    [8, 8, 'left', 'top'], [-8, 8, 'right', 'top']]);
}

/**
 * Drawn walker paths (the several-people view, multi.js): per path {x0, y0, x1, y1} (m) a start
 * ring and an arrow to its end, as the single drawn trajectory's, each labelled with its walker's
 * label (its place, 0 first). Returns the paths drawn, [[x0, y0, x1, y1], …] m.
 */
export function drawPathArrows(ctx, view, paths) {
  clipTo(ctx, view.rect);
  const taken = [];
  paths.forEach((d, i) => {
    drawArrow(ctx, view, { ...d, label: '' });
    ctx.font = FONT_B;
    ctx.fillStyle = ARROW;
    const a = view.toPixel(d.x0, d.y0);
    placeLabel(ctx, `walker ${i}`, a, view.rect, taken, [[8, 8, 'left', 'top'], [-8, 8, 'right', 'top'],
      [8, -8, 'left', 'bottom'], [-8, -8, 'right', 'bottom']]);
  });
  ctx.restore();
  return paths.map((d) => [d.x0, d.y0, d.x1, d.y1]);
}

/**
 * The track layers. `tr` = {data (Track.data()), step, magnify, drawn: {x0, y0, x1, y1, label} | null}.
 * Ellipses every `stride` steps up to the current one are drawn faintly, the current one bold.
 * Returns what was drawn, for the hooks: {filter, step, truth (the whole path, m), track (the
 * estimates drawn, m), label (the drawn trajectory's label box, CSS px) | null}.
 */
export function drawTrack(ctx, view, tr) {
  clipTo(ctx, view.rect);
  const d = tr.data;
  const out = { filter: d ? d.filter : null, step: null, truth: [], track: [], label: null };
  if (d) {
    const step = Math.min(tr.step, d.truth.length - 1);
    // Truth: the whole path dashed, the part already travelled brighter, on a dark halo.
    const travelled = d.truth.slice(0, step + 1);
    ctx.lineJoin = 'round';
    halo(ctx, view, d.truth, 4);
    ctx.lineWidth = 1.5;
    ctx.setLineDash([5, 4]);
    ctx.strokeStyle = 'rgba(255,255,255,0.45)';
    polyline(ctx, view, d.truth, false); ctx.stroke();
    ctx.strokeStyle = TRUTH;
    polyline(ctx, view, travelled, false); ctx.stroke();
    ctx.setLineDash([]);
    const s = view.toPixel(d.truth[0][0], d.truth[0][1]);
    ctx.beginPath(); ctx.arc(s.x, s.y, 3.5, 0, FULL);
    ctx.fillStyle = TRUTH; ctx.fill();
    // The filter's 1σ ellipses (magnified) along the travelled part, then the current one.
    const stride = Math.max(1, Math.round(d.truth.length / 20));
    ctx.lineWidth = 1;
    ctx.strokeStyle = 'rgba(255,169,77,0.3)';
    for (let n = stride; n < step; n += stride) {
      if (d.ellipses[n]) { ellipsePath(ctx, view, d.ellipses[n], tr.magnify); ctx.stroke(); }
    }
    // The filter's track up to now.
    const track = d.estimates.slice(0, step + 1);
    Object.assign(out, { step, truth: d.truth.map((p) => [p[0], p[1]]), track: track.map((p) => [p[0], p[1]]) });
    halo(ctx, view, track, 4.5);
    ctx.strokeStyle = EKF;
    ctx.lineWidth = 2;
    polyline(ctx, view, track, false); ctx.stroke();
    const e = d.ellipses[step];
    if (e) {
      ellipsePath(ctx, view, e, tr.magnify);
      ctx.fillStyle = 'rgba(255,169,77,0.18)'; ctx.fill();
      ctx.lineWidth = 2; ctx.strokeStyle = EKF; ctx.stroke();
    }
  }
  if (tr.drawn) out.label = drawArrow(ctx, view, tr.drawn);
  ctx.restore();
  return out;
}
