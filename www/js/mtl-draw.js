// Drawing of the multi-target mode: every number (ellipses, seeds, hypotheses, detections, LoS
// segments, ticks) comes from the wasm core's view; this file only places it on the canvas
// through the view transform. Markers of the scene (nodes, targets, discs) are drawn from the
// scene itself so they follow a drag at once.

import { C, FONT_B, FULL, clipTo, cross, drawAxes, drawNodes, drawScaleBar, ellipsePath, focusRing, isSelected, linkColor, placeLabel, plotFocus, ring } from './draw.js';

// The colours are the theme's (C, from the CSS variables its legend #legend-mtl uses: draw.js
// applyThemeColors), so the legend and the drawing agree in both themes.

/**
 * The colours this frame draws with, by legend symbol (the CSS variable each comes from): for
 * the hook (mtl.state().colors) and the drawing alike.
 */
export function mtlColors() {
  return {
    bg: C.bg, region: C.bg, regionEdge: C.regionEdge, disc: C.discFill, discEdge: C.discEdge,
    blocked: C.blocked, los: C.los, seed: C.seed, hyp: C.hyp, hypRej: C.hypRej, detected: C.det,
    fa: C.fa, target: C.marker, halo: C.halo, casing: C.casing,
  };
}

/** The region R (the scene's rectangle): the plot background in a dashed frame. */
function region(ctx, view, scene, col) {
  const [x0, x1, y0, y1] = scene.region;
  const a = view.toPixel(x0, y1);
  const b = view.toPixel(x1, y0);
  ctx.fillStyle = col.region;
  ctx.fillRect(a.x, a.y, b.x - a.x, b.y - a.y);
  ctx.strokeStyle = col.regionEdge;
  ctx.setLineDash([6, 4]);
  ctx.lineWidth = 1;
  ctx.strokeRect(a.x, a.y, b.x - a.x, b.y - a.y);
  ctx.setLineDash([]);
}

/**
 * Range ellipses in their link's colour over the theme's casing (none on the dark; on the light
 * one the yellow and off-white links read on white): DP solid, clutter dashed and faint; the
 * ranges a detection uses bold.
 */
function ellipses(ctx, view, v, col) {
  const cased = col.casing && col.casing !== 'transparent';
  for (const t of v.trps) {
    const color = linkColor(t.trp);
    for (const r of t.ranges) {
      if (!r.ellipse) continue;
      const used = r.matched_by.length > 0;
      ctx.strokeStyle = color;
      if (r.source === 'dp') {
        ctx.setLineDash([]);
        ctx.globalAlpha = used ? 0.95 : 0.55;
        ctx.lineWidth = used ? 2 : 1;
      } else {
        ctx.setLineDash([2, 5]);
        ctx.globalAlpha = used ? 0.9 : 0.35;
        ctx.lineWidth = used ? 2 : 1;
      }
      ellipsePath(ctx, view, r.ellipse);
      if (cased) {
        // As faint as the line it cases, so faint ranges stay faint.
        const width = ctx.lineWidth;
        ctx.strokeStyle = col.casing; ctx.lineWidth = width + 2;
        ctx.stroke();
        ctx.strokeStyle = color; ctx.lineWidth = width;
      }
      ctx.stroke();
    }
  }
  ctx.setLineDash([]);
  ctx.globalAlpha = 1;
}

/** Node–target segments: LoS faint, blocked dashed red. */
function segments(ctx, view, v, col) {
  ctx.lineWidth = 1.25;
  for (const s of v.segments) {
    const a = view.toPixel(s.a[0], s.a[1]);
    const b = view.toPixel(s.b[0], s.b[1]);
    ctx.strokeStyle = s.blocked ? col.blocked : col.los;
    ctx.setLineDash(s.blocked ? [6, 4] : []);
    ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
  }
  ctx.setLineDash([]);
}

function dot(ctx, p, r, fill) {
  ctx.beginPath(); ctx.arc(p.x, p.y, r, 0, FULL);
  ctx.fillStyle = fill; ctx.fill();
}

function candidates(ctx, view, v, col) {
  for (const s of v.seeds) dot(ctx, view.toPixel(s.x[0], s.x[1]), 1.6, col.seed);
  ctx.lineWidth = 1.25;
  for (const h of v.hypotheses) {
    const p = view.toPixel(h.x[0], h.x[1]);
    ctx.beginPath(); ctx.arc(p.x, p.y, 3.5, 0, FULL);
    ctx.strokeStyle = h.accepted ? col.hyp : col.hypRej; ctx.stroke();
  }
}

/** Where a detection's label may go around its ring ([dx, dy, align, baseline]), first choice first. */
const DET_SPOTS = [[-12, -8, 'right', 'bottom'], [12, -8, 'left', 'bottom'], [-12, 8, 'right', 'top'],
  [12, 8, 'left', 'top'], [0, -13, 'center', 'bottom'], [0, 13, 'center', 'top']];
/** Where a target's label may go beside its cross. */
const TARGET_SPOTS = [[9, 6, 'left', 'top'], [9, -6, 'left', 'bottom'], [-9, 6, 'right', 'top'], [-9, -6, 'right', 'bottom']];

/**
 * The detections: a ring each, then their labels (#1, #2 FA, …) placed clear of one another
 * (placeLabel) inside `rect`; each label's box goes to `labels` ({text, kind, box}).
 */
function detections(ctx, view, v, rect, taken, labels, col) {
  ctx.font = FONT_B;
  const at = v.detected.map((d) => {
    const p = view.toPixel(d.x[0], d.x[1]);
    const color = d.hit ? col.detected : col.fa;
    ctx.beginPath(); ctx.arc(p.x, p.y, 10, 0, FULL);
    ctx.lineWidth = 4; ctx.strokeStyle = col.halo; ctx.stroke();
    ctx.lineWidth = 2.25; ctx.strokeStyle = color; ctx.stroke();
    dot(ctx, p, 2.5, color);
    return { p, color };
  });
  v.detected.forEach((d, i) => {
    const text = `#${i + 1}${d.hit ? '' : ' FA'}`;
    ctx.fillStyle = at[i].color;
    labels.push({ text, kind: 'detection', box: placeLabel(ctx, text, at[i].p, rect, taken, DET_SPOTS, col.halo) });
  });
}

function discs(ctx, view, scene, sel, col) {
  const r = view.len(scene.diameter / 2);
  scene.discs.forEach((c, i) => {
    const p = view.toPixel(c[0], c[1]);
    ctx.beginPath(); ctx.arc(p.x, p.y, r, 0, FULL);
    ctx.fillStyle = col.disc; ctx.fill();
    const on = isSelected(sel, 'disc', i);
    ctx.lineWidth = on ? 2.5 : 1;
    ctx.strokeStyle = on ? C.sel : col.discEdge;
    ctx.stroke();
    if (on && plotFocus.on) focusRing(ctx, p, r + 4);
  });
}

/** The targets' crosses, then their labels (clear of the detections' and one another's, as there). */
function targets(ctx, view, scene, v, sel, rect, taken, labels, col) {
  const at = scene.targets.map((q, k) => {
    const p = view.toPixel(q[0], q[1]);
    if (isSelected(sel, 'target', k)) ring(ctx, p, 12);
    cross(ctx, p, 7, col.halo, 5);
    cross(ctx, p, 7, col.target, 2.25);
    return p;
  });
  ctx.font = FONT_B;
  ctx.fillStyle = col.target;
  scene.targets.forEach((q, k) => {
    const t = v && v.targets[k];
    const text = t ? `T${k + 1} · ${t.dp_trps.length} DP` : `T${k + 1}`;
    labels.push({ text, kind: 'target', box: placeLabel(ctx, text, at[k], rect, taken, TARGET_SPOTS, col.halo) });
  });
}

/**
 * The whole canvas: `scene` (markers, current), `v` (the core's last view or null), `sel` (the
 * selected object), `w` (the wasm module, for axis ticks). The labels of the detections and
 * targets drawn go to `view.drawn.labels` ([{text, kind: 'detection' | 'target', box: {x, y, w,
 * h} CSS px}]); the colours drawn with (mtlColors) to `view.drawn.colors`.
 */
export function drawMtl(view, scene, v, sel, w) {
  const ctx = view.context();
  const col = mtlColors();
  view.drawn.colors = col;
  view.clear(ctx, col.bg);
  const r = view.rect;
  // Zoomed in (zoom.js), everything stays inside the plot; at the home extent the node labels may
  // reach into the margin.
  const zoomed = view.zoomed();
  if (zoomed) clipTo(ctx, r);
  region(ctx, view, scene, col);
  if (zoomed) ctx.restore();
  drawAxes(ctx, view, w);
  clipTo(ctx, r);
  if (v) {
    ellipses(ctx, view, v, col);
    segments(ctx, view, v, col);
  }
  discs(ctx, view, scene, sel, col);
  if (v) candidates(ctx, view, v, col);
  ctx.restore();
  if (zoomed) clipTo(ctx, r);
  // Labels stay inside the plot when zoomed (it clips), else inside the canvas.
  const room = zoomed ? r : { x: 0, y: 0, w: view.width, h: view.height };
  const taken = [];
  const labels = [];
  if (v) detections(ctx, view, v, room, taken, labels, col);
  targets(ctx, view, scene, v, sel, room, taken, labels, col);
  view.drawn.labels = labels;
  const named = (prefix) => (q, i) => ({ x: q[0], y: q[1], name: `${prefix}${i + 1}` });
  drawNodes(ctx, view, scene.receivers.map(named('Rx')), scene.transmitters.map(named('Tx')), sel);
  if (zoomed) ctx.restore();
  drawScaleBar(ctx, view, w);
}
