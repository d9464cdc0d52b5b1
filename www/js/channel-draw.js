// The channel view's layer on the map (drawn under the node markers, draw.js drawScene's
// overlay): at the time cursor's snapshot, the true path (dashed, the part walked so far
// brighter) and the person's true position, the links whose delay the filter used (their
// baseline in the link's colour) with the iso-delay ellipse of that delay, the track's segments
// up to the cursor (each its own line, a lost one ending in a ring; nothing between them) and
// the filter's 1σ position ellipse. Over the error chart drawn by the core, the segments
// (drawSegments: the time outside them shaded, each loss a dashed line with its reason), and
// the time cursor over both charts. Every number comes from the core (ChannelFigures.overlay,
// TRACK.json's segments, the charts' plot boxes) or the truth file; this file only places them.

import { C, FULL, clipTo, cross, ellipsePath, linkColor, polyline } from './draw.js';

const TRUTH = 'rgba(255,255,255,0.9)';

/**
 * The time cursor's colour over the charts: a magenta none of the charts' own marks use (the
 * truth is vermillion, the estimates blue, the statics grey, a loss red, a start green); the
 * legend under the delay chart shows it (index.html, .sym.chan-cursor).
 */
export const CURSOR_COLOR = 'rgb(190, 0, 140)';

/** The reasons a segment ends (TRACK.json `segments[].end`) as the page names them. */
const LOSS_NAMES = { innovation: 'innovation', misses: 'misses', outside_area: 'outside area', filter: 'filter failure', end: 'end of the recording' };

/** A segment's `end` as text ("outside area"; an unknown one as written). */
export function lossName(end) {
  return LOSS_NAMES[end] || String(end).replace(/_/g, ' ');
}

/** A dark line under a path, so it reads on every map colour. */
function halo(ctx, view, points, width) {
  ctx.strokeStyle = 'rgba(10,12,18,0.55)';
  ctx.lineWidth = width;
  polyline(ctx, view, points, false);
  ctx.stroke();
}

/**
 * Draws the layer. `d` = {overlay (ChannelFigures.overlay(k)), truth: [[x, y] | null per
 * snapshot] | null, step, nodes (App.nodes()), stale (the result's inputs changed since the
 * run: its track, 1σ and estimate are drawn faded and the track dashed)}. Returns what was
 * drawn, for the hooks: {step, estimate: [x, y] | null, sigma: ellipse | null, links: [link
 * index…], truth: [x, y] | null, track_points (positions drawn), track_runs (segments drawn,
 * each its own line), segment (the overlay's segment index | null), stale}.
 */
export function drawChannel(ctx, view, d) {
  const ov = d.overlay;
  const stale = !!d.stale;
  const drawn = { step: d.step, estimate: null, sigma: null, links: [], truth: null, track_points: 0, track_runs: 0, segment: null, stale };
  clipTo(ctx, view.rect);
  ctx.lineJoin = 'round';
  // The true path: whole and dashed, the part walked so far brighter.
  if (d.truth) {
    const runs = [];
    let run = [];
    d.truth.forEach((p, k) => {
      if (p) run.push(p);
      if ((!p || k === d.truth.length - 1) && run.length) { runs.push(run); run = []; }
    });
    const walked = d.truth.slice(0, d.step + 1).filter(Boolean);
    ctx.setLineDash([5, 4]);
    for (const r of runs) {
      halo(ctx, view, r, 4);
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = 'rgba(255,255,255,0.4)';
      polyline(ctx, view, r, false); ctx.stroke();
    }
    if (walked.length > 1) {
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = TRUTH;
      polyline(ctx, view, walked, false); ctx.stroke();
    }
    ctx.setLineDash([]);
  }
  if (ov) {
    // The links used at this snapshot: baseline in the link's colour, and the iso-delay
    // ellipse of the delay the filter took.
    const n = d.nodes;
    for (const l of ov.links) {
      const color = linkColor(l.link);
      const tx = n.transmitters[l.tx];
      const rx = n.receivers[l.rx];
      if (tx && rx) {
        const a = view.toPixel(tx.x, tx.y);
        const b = view.toPixel(rx.x, rx.y);
        ctx.strokeStyle = 'rgba(10,12,18,0.6)';
        ctx.lineWidth = 5;
        ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
        ctx.strokeStyle = color;
        ctx.lineWidth = 3;
        ctx.stroke();
      }
      if (l.ellipse) {
        ctx.strokeStyle = color;
        ctx.globalAlpha = 0.8;
        ctx.lineWidth = 1.25;
        ellipsePath(ctx, view, l.ellipse);
        ctx.stroke();
        ctx.globalAlpha = 1;
      }
      drawn.links.push(l.link);
    }
    // The segments so far (one line each, never joined across a gap: no position is drawn
    // outside a segment) and the filter's 1σ.
    const runs = ov.track_m || [];
    drawn.segment = ov.segment ?? null;
    drawn.track_runs = runs.length;
    // A stale result (computed with other nodes or settings): faded, the track dashed.
    if (stale) ctx.globalAlpha = 0.45;
    runs.forEach((run, i) => {
      drawn.track_points += run.length;
      if (run.length > 1) {
        if (stale) ctx.setLineDash([6, 5]);
        halo(ctx, view, run, 4.5);
        ctx.strokeStyle = C.fix;
        ctx.lineWidth = 2;
        polyline(ctx, view, run, false); ctx.stroke();
        ctx.setLineDash([]);
      }
      // A segment that has ended by now: a ring where it was lost.
      if (i !== ov.segment && run.length) {
        const p = view.toPixel(run[run.length - 1][0], run[run.length - 1][1]);
        ctx.beginPath(); ctx.arc(p.x, p.y, 4.5, 0, FULL);
        ctx.lineWidth = 3; ctx.strokeStyle = 'rgba(10,12,18,0.6)'; ctx.stroke();
        ctx.lineWidth = 1.5; ctx.strokeStyle = C.fix; ctx.stroke();
      }
    });
    if (ov.sigma_ellipse) {
      ellipsePath(ctx, view, ov.sigma_ellipse);
      ctx.fillStyle = 'rgba(255,169,77,0.18)'; ctx.fill();
      ctx.lineWidth = 2; ctx.strokeStyle = C.fix; ctx.stroke();
      drawn.sigma = ov.sigma_ellipse;
    }
    if (ov.state) {
      const p = view.toPixel(ov.state[0], ov.state[1]);
      ctx.beginPath(); ctx.arc(p.x, p.y, 4, 0, FULL);
      ctx.fillStyle = C.fix; ctx.fill();
      ctx.lineWidth = 1.5; ctx.strokeStyle = '#1b1f27'; ctx.stroke();
      drawn.estimate = [ov.state[0], ov.state[1]];
    }
    ctx.globalAlpha = 1;
  }
  const t = d.truth && d.truth[d.step];
  if (t) {
    const p = view.toPixel(t[0], t[1]);
    cross(ctx, p, 6, '#0d1017', 4);
    cross(ctx, p, 6, '#ffffff', 2);
    drawn.truth = [t[0], t[1]];
  }
  ctx.restore();
  return drawn;
}

/**
 * The time cursor over a chart drawn by the core: a vertical line in CURSOR_COLOR at time `t_s` inside `box`
 * ({x_px: [left, right], y_px: [top, bottom], t_range_s: [t0, t1]}, the canvas' backing
 * pixels) on the transparent canvas `cursor` laid over the chart (same backing size). Returns
 * the line's x (backing pixels) or null when nothing is drawn.
 */
export function drawCursor(cursor, box, t_s, width, height) {
  if (cursor.width !== width || cursor.height !== height) {
    cursor.width = width;
    cursor.height = height;
  }
  const ctx = cursor.getContext('2d');
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, cursor.width, cursor.height);
  if (!box || t_s === null || t_s === undefined) return null;
  const [x0, x1] = box.x_px;
  const [y0, y1] = box.y_px;
  const [t0, t1] = box.t_range_s;
  if (!(t1 > t0) || !(x1 > x0)) return null;
  const x = x0 + ((t_s - t0) / (t1 - t0)) * (x1 - x0);
  if (!(x >= x0 - 0.5 && x <= x1 + 0.5)) return null;
  const dpr = window.devicePixelRatio || 1;
  ctx.lineWidth = Math.max(1, 2 * dpr);
  ctx.strokeStyle = CURSOR_COLOR;
  ctx.beginPath();
  ctx.moveTo(Math.round(x) + 0.5, y0);
  ctx.lineTo(Math.round(x) + 0.5, y1);
  ctx.stroke();
  return x;
}

/**
 * The track's segments over the error chart the core drew on `canvas` (its plot `box`, as
 * drawCursor's): the time outside every segment shaded grey (before the first, between two,
 * after the last; all of it when there is none), at each loss (the first snapshot after a
 * segment that did not last to the end of the recording) a dashed red line labelled with its
 * reason ("lost: innovation"), at each start a green tick on the time axis. `segments` are
 * TRACK.json's, `t_s` its times. Returns what was drawn (backing pixels), for the hooks:
 * {gaps: [[x0, x1]…], losses: [{x, t_s, end, label}…], starts: [x…]}, or null without a box.
 */
export function drawSegments(canvas, box, segments, t_s) {
  if (!box || !t_s || !t_s.length) return null;
  const [x0, x1] = box.x_px;
  const [y0, y1] = box.y_px;
  const [t0, t1] = box.t_range_s;
  if (!(t1 > t0) || !(x1 > x0)) return null;
  const at = (t) => Math.max(x0, Math.min(x1, x0 + ((t - t0) / (t1 - t0)) * (x1 - x0)));
  const dpr = window.devicePixelRatio || 1;
  const ctx = canvas.getContext('2d');
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  const out = { gaps: [], losses: [], starts: [] };
  // The stretches of time outside the segments.
  const tEnd = t_s[t_s.length - 1];
  const gaps = [];
  let from = t_s[0]; // the end of the previous segment (the start: none yet)
  for (const g of segments) {
    if (g.t_first_s > from) gaps.push([from, g.t_first_s]);
    from = g.t_last_s;
  }
  if (!segments.length) gaps.push([t_s[0], tEnd]);
  else if (segments[segments.length - 1].last < t_s.length - 1) gaps.push([from, tEnd]);
  ctx.fillStyle = 'rgba(110, 118, 130, 0.16)';
  for (const [a, b] of gaps) {
    const [xa, xb] = [at(a), at(b)];
    if (xb > xa) ctx.fillRect(xa, y0, xb - xa, y1 - y0);
    out.gaps.push([xa, xb]);
  }
  // The starts: a tick up from the time axis.
  ctx.strokeStyle = 'rgba(0, 140, 70, 0.95)';
  ctx.lineWidth = Math.max(1, 2 * dpr);
  for (const g of segments) {
    const x = Math.round(at(g.t_first_s)) + 0.5;
    ctx.beginPath(); ctx.moveTo(x, y1); ctx.lineTo(x, y1 - 10 * dpr); ctx.stroke();
    out.starts.push(x);
  }
  // The losses: a dashed line at the snapshot of the loss, its reason next to it.
  ctx.font = `${Math.round(11 * dpr)}px sans-serif`;
  ctx.textBaseline = 'top';
  segments.filter((g) => g.end !== 'end').forEach((g, i) => {
    const t = t_s[Math.min(g.last + 1, t_s.length - 1)];
    const x = Math.round(at(t)) + 0.5;
    ctx.strokeStyle = 'rgba(200, 30, 30, 0.9)';
    ctx.lineWidth = Math.max(1, 1.5 * dpr);
    ctx.setLineDash([5 * dpr, 4 * dpr]);
    ctx.beginPath(); ctx.moveTo(x, y0); ctx.lineTo(x, y1); ctx.stroke();
    ctx.setLineDash([]);
    const label = `lost: ${lossName(g.end)}`;
    const w = ctx.measureText(label).width;
    // Right of the line, or left of it near the right edge; rows alternate so close losses stay legible.
    const tx = x + 4 * dpr + w <= x1 ? x + 4 * dpr : x - 4 * dpr - w;
    const ty = y0 + (22 + (i % 2) * 15) * dpr;
    ctx.fillStyle = 'rgba(255, 255, 255, 0.85)';
    ctx.fillRect(tx - 2 * dpr, ty - 1 * dpr, w + 4 * dpr, 14 * dpr);
    ctx.fillStyle = 'rgb(170, 20, 20)';
    ctx.fillText(label, tx, ty);
    out.losses.push({ x, t_s: t, end: g.end, label });
  });
  ctx.restore();
  return out;
}
