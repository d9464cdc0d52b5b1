// Mouse/pointer handling on the plot for the snapshot and tracking views: drag Tx/Rx markers,
// click to place a target (snapshot mode), press-and-drag a trajectory (tracking mode, "draw") or
// the Plan panel's region of interest (after "Draw ROI", plan.js), press-and-drag on empty map to
// pan (zoom.js), hover read-out (with Doppler on in the snapshot view, the position and
// velocity bounds with Doppler and the delay-only one: App.doppler_at). A node drag cancels a
// running plan. pickNearest is the hit test of every view (mtl.js uses it too).

import { $, errorText, fixed, showError, clearError } from './dom.js';

const HIT_PX = 12; // pick radius around a marker, CSS px (mouse)
const TOUCH_HIT_PX = 22; // the same for a finger or pen: a target about 44 CSS px across
const CLICK_PX = 4; // a press that moves less than this is a click
const DOUBLE_MS = 500; // a second click this soon after the first and …
const DOUBLE_PX = 8; // … this close to it is the second click of a double-click (zoom.js: fit)

/** The pick radius for a pointer event: finger-sized for touch and pen, HIT_PX for a mouse. */
export const hitRadius = (ev) => (ev && (ev.pointerType === 'touch' || ev.pointerType === 'pen') ? TOUCH_HIT_PX : HIT_PX);

/**
 * The object nearest to canvas pixel `p` within `radius` CSS px (HIT_PX by default; hitRadius(ev)
 * for a press), or null: `groups` = [[kind, points, extraPx = 0], …] with points [x, y] or {x, y}
 * (m) and `extraPx` their radius on screen; on a tie the later group wins. Returns {kind, index}.
 */
export function pickNearest(view, groups, p, radius = HIT_PX) {
  let best = null;
  let bestD = radius;
  for (const [kind, list, extra = 0] of groups) {
    list.forEach((q, index) => {
      const c = Array.isArray(q) ? view.toPixel(q[0], q[1]) : view.toPixel(q.x, q.y);
      const d = Math.hypot(c.x - p.x, c.y - p.y) - extra;
      if (d <= bestD) { best = { kind, index }; bestD = d; }
    });
  }
  return best;
}

/** The Tx/Rx node under a canvas pixel ({kind, index}), or null. */
export const hitNode = (view, nodes, p, radius) =>
  pickNearest(view, [['rx', nodes.receivers], ['tx', nodes.transmitters]], p, radius);

/**
 * Moves Tx/Rx `node` ({kind, index}) to (x, y) m and marks the map, geometry and panel stale as
 * a drag does (the map reduced until the drag's end asks for it in full): the one path of a
 * mouse drag and a keyboard move (keyboard.js). A rejected position shows the core's message.
 */
export function moveNode(ctx, node, x, y) {
  try {
    if (node.kind === 'tx') ctx.app.move_transmitter(node.index, x, y);
    else ctx.app.move_receiver(node.index, x, y);
    clearError();
    ctx.changed({ all: true, dragging: true });
    return true;
  } catch (e) {
    showError(errorText(e));
    return false;
  }
}

export function attachPointer(ctx) {
  const { view, st, app } = ctx;
  const canvas = view.canvas;
  const readout = $('readout');
  let press = null; // { start, last, anchor (of the pan): {x, y}, node: {kind, index} | null, target, moved, draw, roi, pan }
  // The last click that placed a target: {t (ms), p (pixel), before (st.target before it)}; a
  // double-click that fits the zoom puts the target back (undoDoubleClick, zoom.js).
  let lastClick = null;

  const hover = (p) => {
    if (!view.inPlot(p.x, p.y)) {
      if (st.mode === 'mtl') readout.textContent = 'Multi-target · drag Tx, Rx, targets (×) and discs';
      else if (st.mode === 'channel') readout.textContent = 'Channel · open, drop or simulate a recording, then Run · drag Tx/Rx markers · wheel to zoom';
      else if (ctx.plan && ctx.plan.wantsRoi()) readout.textContent = 'Press and drag on the map to draw the region of interest';
      else readout.textContent = st.mode !== 'tracking'
        ? 'Move over the map to read the bound · drag Tx/Rx markers · click to place a target, drag it to move it · ? for help'
        : `Move over the map to read the bound · drag Tx/Rx markers${ctx.tracking.wantsDraw() ? ` · ${ctx.tracking.drawHint()}` : ''}`;
      return;
    }
    const m = view.toMetre(p.x, p.y);
    // With Doppler shown (doppler.js), the bound of the main map and the velocity map beside it.
    const job = ctx.doppler ? ctx.doppler.job() : null;
    if (job) {
      const d = app.doppler_at(m.x, m.y, JSON.stringify(job));
      const bold = (t) => { const e = document.createElement('b'); e.textContent = t; return e; };
      readout.replaceChildren(
        `x = ${fixed(m.x, 2)} m, y = ${fixed(m.y, 2)} m  ·  with Doppler: position bound `, bold(d.position_label),
        ', velocity bound ', bold(d.velocity_label),
        `  ·  delays only ${d.delay_only_label}`,
        d.bounded ? '' : '  ·  Fisher matrix singular here',
        st.colourLock && d.position_rmse_m !== null ? st.colourLock.note(d.position_rmse_m) : '',
      );
      return;
    }
    const c = app.crlb_at(m.x, m.y);
    readout.replaceChildren();
    const b = document.createElement('b');
    b.textContent = c.rmse_label;
    readout.append(
      `x = ${fixed(m.x, 2)} m, y = ${fixed(m.y, 2)} m  ·  RMSE bound `, b,
      c.bounded ? `  ·  σx ${c.sigma_x_label}, σy ${c.sigma_y_label}` : '  ·  Fisher matrix singular here',
      st.colourLock ? st.colourLock.note(c.rmse_m) : '',
    );
  };

  canvas.addEventListener('pointerdown', (ev) => {
    if (ev.button !== 0) return;
    const p = view.eventPixel(ev);
    // "Draw ROI" armed: the press draws the ROI, even over a node.
    const roi = !!ctx.plan && ctx.plan.wantsRoi() && view.inPlot(p.x, p.y);
    const node = roi ? null : hitNode(view, st.nodes, p, hitRadius(ev));
    // The placed target (snapshot view) is dragged like a node.
    const target = !node && !roi && st.mode === 'snapshot' && !!st.target
      && !!pickNearest(view, [['target', [st.target]]], p, hitRadius(ev));
    const draw = !node && !roi && !target && view.inPlot(p.x, p.y) && ctx.tracking.wantsDraw();
    // Anything else in the plot: a click (snapshot: place the target) or, once it moves, a pan.
    const pan = !node && !roi && !draw && !target && view.inPlot(p.x, p.y);
    press = { start: p, last: p, anchor: p, node, target, moved: false, draw, roi, pan };
    if (target) canvas.classList.add('dragging');
    if (roi) ctx.plan.roiStart(p);
    if (node) {
      ctx.panel.select(node.kind, node.index);
      canvas.classList.add('dragging');
    }
    if (draw) ctx.tracking.drawStart(view.toMetre(p.x, p.y));
    canvas.setPointerCapture(ev.pointerId);
    ev.preventDefault();
  });

  canvas.addEventListener('pointermove', (ev) => {
    const p = view.eventPixel(ev);
    if (press && press.node) {
      if (!press.moved && ctx.plan) ctx.plan.cancel('node dragged');
      press.moved = true;
      // Keep the node inside the scenario area and the window shown (clamped in pixels).
      const box = view.dragBox();
      const m = view.toMetreWithin(p, box.a, box.b);
      moveNode(ctx, press.node, m.x, m.y);
    } else if (press && press.target) {
      if (Math.hypot(p.x - press.start.x, p.y - press.start.y) > CLICK_PX) press.moved = true;
      if (press.moved) {
        const box = view.dragBox();
        const m = view.toMetreWithin(p, box.a, box.b);
        // The same noise realisation follows the target (New noise draws another).
        st.target = { x: m.x, y: m.y, seed: st.target.seed };
        ctx.changed({ target: true });
      }
    } else if (press && press.roi) {
      ctx.plan.roiMove(p);
    } else if (press && press.draw) {
      ctx.tracking.drawMove(view.toMetre(p.x, p.y));
    } else if (press) {
      if (Math.hypot(p.x - press.start.x, p.y - press.start.y) > CLICK_PX) press.moved = true;
      if (press.pan && press.moved) {
        ctx.zoom.panBy(p.x - press.anchor.x, p.y - press.anchor.y); // the map follows the pointer
        press.anchor = p;
      }
    } else {
      canvas.classList.toggle('over-node', !!hitNode(view, st.nodes, p)
        || (st.mode === 'snapshot' && !!st.target && !!pickNearest(view, [['target', [st.target]]], p)));
    }
    if (press) press.last = p;
    hover(p);
  });

  /**
   * The press ends at canvas pixel p; `up`: released (not cancelled); `shift`: Shift was held
   * (a Shift+click pins the probe there instead of placing the target).
   */
  const finish = (p, up, shift = false) => {
    const wasClick = up && !press.node && !press.roi && !press.moved && st.mode !== 'tracking' && st.mode !== 'channel';
    if (press.roi) ctx.plan.roiEnd(p, up);
    if (press.draw) ctx.tracking.drawEnd(view.toMetre(p.x, p.y));
    // A map reduced while dragging (map.js) is now computed at full resolution.
    if (press.node && press.moved) ctx.changed({ map: true, dragEnd: true });
    if (press.pan && press.moved) {
      // The release point is where the map ends up (a move event may have been resampled).
      if (up) ctx.zoom.panBy(p.x - press.anchor.x, p.y - press.anchor.y);
      ctx.zoom.settle();
    }
    press = null;
    canvas.classList.remove('dragging');
    const now = performance.now();
    const second = !!lastClick && !lastClick.second && now - lastClick.t < DOUBLE_MS
      && Math.hypot(p.x - lastClick.p.x, p.y - lastClick.p.y) < DOUBLE_PX;
    if (wasClick && view.inPlot(p.x, p.y)) {
      const m = view.toMetre(p.x, p.y);
      if (shift && ctx.pinProbe) {
        ctx.pinProbe(m.x, m.y);
      } else if (!second) {
        // The second click of a double-click places nothing (the double-click may fit the zoom).
        lastClick = { t: now, p, before: st.target ? { ...st.target } : null };
        ctx.placeTarget(m.x, m.y);
        return;
      }
    }
    if (second) lastClick.second = true; else lastClick = null;
  };
  const end = (ev) => {
    if (press) finish(view.eventPixel(ev), ev.type === 'pointerup', !!ev.shiftKey);
  };
  // A second finger (a pinch, zoom.js) ends the press where it is, as a cancel.
  ctx.zoom.cancelPress.push(() => { if (press) finish(press.last, false); });
  canvas.addEventListener('pointerup', end);
  canvas.addEventListener('pointercancel', end);
  canvas.addEventListener('pointerleave', () => { if (!press) hover({ x: -1, y: -1 }); });
  /**
   * A double-click fitted the zoom (zoom.js): the target its first click placed goes back to
   * where it was (or away), so the double-click changes the window only.
   */
  const undoDoubleClick = () => {
    if (!lastClick || performance.now() - lastClick.t > 2 * DOUBLE_MS) return;
    st.target = lastClick.before;
    lastClick = null;
    ctx.changed({ target: true });
  };
  return { showHint: () => hover({ x: -1, y: -1 }), undoDoubleClick };
}
