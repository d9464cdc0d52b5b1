// The channel view's layer on the map (drawn under the node markers, draw.js drawScene's
// overlay): at the time cursor's snapshot, the true path (dashed, the part walked so far
// brighter) and the person's true position, the links whose delay the filter used (their
// baseline in the link's colour) with the iso-delay ellipse of that delay, the track up to the
// cursor and the filter's 1σ position ellipse. Every number comes from the core
// (ChannelFigures.overlay) or the truth file; this file only places them.

import { C, FULL, clipTo, cross, ellipsePath, linkColor, polyline } from './draw.js';

const TRUTH = 'rgba(255,255,255,0.9)';

/** A dark line under a path, so it reads on every map colour. */
function halo(ctx, view, points, width) {
  ctx.strokeStyle = 'rgba(10,12,18,0.55)';
  ctx.lineWidth = width;
  polyline(ctx, view, points, false);
  ctx.stroke();
}

/**
 * Draws the layer. `d` = {overlay (ChannelFigures.overlay(k)), truth: [[x, y] | null per
 * snapshot] | null, step, nodes (App.nodes())}. Returns what was drawn, for the hooks:
 * {step, estimate: [x, y] | null, sigma: ellipse | null, links: [link index…], truth: [x, y] |
 * null, track_points}.
 */
export function drawChannel(ctx, view, d) {
  const ov = d.overlay;
  const drawn = { step: d.step, estimate: null, sigma: null, links: [], truth: null, track_points: 0 };
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
    // The track so far and the filter's 1σ.
    const track = ov.track_m || [];
    drawn.track_points = track.length;
    if (track.length > 1) {
      halo(ctx, view, track, 4.5);
      ctx.strokeStyle = C.fix;
      ctx.lineWidth = 2;
      polyline(ctx, view, track, false); ctx.stroke();
    }
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
 * The time cursor over a chart drawn by the core: a vertical line at time `t_s` inside `box`
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
  ctx.strokeStyle = 'rgba(213, 94, 0, 0.9)';
  ctx.beginPath();
  ctx.moveTo(Math.round(x) + 0.5, y0);
  ctx.lineTo(Math.round(x) + 0.5, y1);
  ctx.stroke();
  return x;
}
