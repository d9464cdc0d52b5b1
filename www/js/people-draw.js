// Several people on the map (issue 41 §2), shared by the tracking view (multi.js, the simulated
// walkers of track_people) and the channel view (channel-player.js, the labelled tracks of a
// recording, as `cir track --targets auto`): the true paths thin and dashed, every labelled track
// up to the step in its own colour, with its label and its current 1σ position ellipse. The
// document is {track: {t_s, targets: [scan][{label, state}], tracks: [{label, first_scan,
// last_scan}]}, ellipses: [scan][ellipse | null per reported target], truth?: {targets:
// [scan][{label, state}]} | null}: the core's numbers; this file only places them.

import { C, FONT_B, FULL, clipTo, ellipsePath, linkColor, placeLabel, polyline } from './draw.js';

/** The colour of the track with `label` in `doc`: its place among the document's tracks (label order). */
export function peopleColour(doc, label) {
  const i = doc.track.tracks.findIndex((t) => t.label === label);
  return linkColor(Math.max(0, i));
}

/** Every true path of `doc.truth`, [[x, y], …] per person (label order); none without a truth. */
export function peopleTruthPaths(doc) {
  const paths = new Map();
  for (const scan of (doc && doc.truth ? doc.truth.targets : [])) {
    for (const t of scan) {
      if (!paths.has(t.label)) paths.set(t.label, []);
      paths.get(t.label).push([t.state[0], t.state[1]]);
    }
  }
  return [...paths.values()];
}

/**
 * Draws the people of `doc` at scan `step` (clamped to the last scan; ellipses magnified by
 * `magnify`; `colourOf(label)` each track's colour). Returns what was drawn: {step, truth: [[x,
 * y]…] per person, tracks: [{label, colour, state, ellipse, points (the track's positions drawn
 * up to the step), box (its label's box)}]} (the tracks reported at the step).
 */
export function drawPeople(ctx, view, doc, step, magnify, colourOf) {
  const d = doc;
  step = Math.max(0, Math.min(step, d.track.t_s.length - 1));
  const layer = { step, truth: [], tracks: [] };
  const base = ctx.globalAlpha; // the caller's fading (a stale result), kept for the fills
  clipTo(ctx, view.rect);
  ctx.lineJoin = 'round';
  ctx.setLineDash([4, 4]);
  ctx.lineWidth = 1;
  ctx.strokeStyle = 'rgba(255,255,255,0.7)';
  for (const path of peopleTruthPaths(d)) {
    polyline(ctx, view, path, false); ctx.stroke();
    layer.truth.push(path);
  }
  ctx.setLineDash([]);
  const taken = [];
  for (const tr of d.track.tracks) {
    const colour = colourOf(tr.label);
    // The track's estimates up to the step, split where it was not reported.
    const runs = [[]];
    for (let k = tr.first_scan; k <= Math.min(step, tr.last_scan); k++) {
      const t = d.track.targets[k].find((x) => x.label === tr.label);
      if (t) runs[runs.length - 1].push([t.state[0], t.state[1]]);
      else if (runs[runs.length - 1].length) runs.push([]);
    }
    ctx.strokeStyle = colour;
    ctx.lineWidth = 2;
    for (const r of runs) if (r.length > 1) { polyline(ctx, view, r, false); ctx.stroke(); }
    const i = d.track.targets[step].findIndex((x) => x.label === tr.label);
    if (i < 0) continue;
    const t = d.track.targets[step][i];
    const e = d.ellipses[step][i];
    if (e) {
      ellipsePath(ctx, view, e, magnify);
      ctx.globalAlpha = 0.2 * base; ctx.fillStyle = colour; ctx.fill(); ctx.globalAlpha = base;
      ctx.lineWidth = 2; ctx.strokeStyle = colour; ctx.stroke();
    }
    const p = view.toPixel(t.state[0], t.state[1]);
    ctx.beginPath(); ctx.arc(p.x, p.y, 4, 0, FULL);
    ctx.fillStyle = colour; ctx.fill();
    ctx.font = FONT_B;
    ctx.fillStyle = colour;
    const box = placeLabel(ctx, `#${t.label}`, p, view.rect, taken, [[7, -6, 'left', 'bottom'],
      [-7, -6, 'right', 'bottom'], [7, 6, 'left', 'top'], [-7, 6, 'right', 'top']], C.halo);
    layer.tracks.push({ label: t.label, colour, state: t.state, ellipse: e, points: runs.flat(), box });
  }
  ctx.restore();
  return layer;
}
