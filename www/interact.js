// Mouse/pointer handling on the plot: drag Tx/Rx markers, click to place a target (snapshot mode) or
// press-and-drag a trajectory (tracking mode, "draw"), hover read-out.

import { showError, clearError } from './panel.js';

const HIT_PX = 12; // pick radius around a marker, CSS px
const CLICK_PX = 4; // a press that moves less than this is a click

/** The node under a canvas pixel, or null. */
export function hitNode(view, nodes, p) {
  let best = null;
  let bestD = HIT_PX;
  const test = (kind, list) => list.forEach((n, index) => {
    const q = view.toPixel(n.x, n.y);
    const d = Math.hypot(q.x - p.x, q.y - p.y);
    if (d <= bestD) { best = { kind, index }; bestD = d; }
  });
  test('rx', nodes.receivers);
  test('tx', nodes.transmitters);
  return best;
}

export function attachPointer(ctx) {
  const { view, st, app } = ctx;
  const canvas = view.canvas;
  const readout = document.getElementById('readout');
  let press = null; // { start: {x, y}, node: {kind, index} | null, moved }

  const hover = (p) => {
    if (!view.inPlot(p.x, p.y)) {
      if (st.mode === 'mtl') readout.textContent = 'Multi-target · drag Tx, Rx, targets (×) and discs';
      else readout.textContent = st.mode !== 'tracking'
        ? 'Move over the map to read the bound · drag Tx/Rx markers · click to place a target'
        : `Move over the map to read the bound · drag Tx/Rx markers${ctx.tracking.wantsDraw() ? ' · press and drag to draw a trajectory' : ''}`;
      return;
    }
    const m = view.toMetre(p.x, p.y);
    const c = app.crlb_at(m.x, m.y);
    readout.replaceChildren();
    const b = document.createElement('b');
    b.textContent = c.rmse_label;
    readout.append(
      `x = ${m.x.toFixed(2)} m, y = ${m.y.toFixed(2)} m  ·  RMSE bound `, b,
      c.bounded ? `  ·  σx ${c.sigma_x_label}, σy ${c.sigma_y_label}` : '  ·  Fisher matrix singular here',
    );
  };

  canvas.addEventListener('pointerdown', (ev) => {
    if (ev.button !== 0) return;
    const p = view.eventPixel(ev);
    const node = hitNode(view, st.nodes, p);
    const draw = !node && view.inPlot(p.x, p.y) && ctx.tracking.wantsDraw();
    press = { start: p, node, moved: false, draw };
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
      press.moved = true;
      // Keep the node inside the plotted area (clamped in pixels).
      const r = view.rect;
      const m = view.toMetre(Math.min(Math.max(p.x, r.x), r.x + r.w), Math.min(Math.max(p.y, r.y), r.y + r.h));
      try {
        if (press.node.kind === 'tx') app.move_transmitter(press.node.index, m.x, m.y);
        else app.move_receiver(press.node.index, m.x, m.y);
        clearError();
        ctx.changed({ all: true, dragging: true });
      } catch (e) {
        showError(e.message);
      }
    } else if (press && press.draw) {
      ctx.tracking.drawMove(view.toMetre(p.x, p.y));
    } else if (press) {
      if (Math.hypot(p.x - press.start.x, p.y - press.start.y) > CLICK_PX) press.moved = true;
    } else {
      canvas.classList.toggle('over-node', !!hitNode(view, st.nodes, p));
    }
    hover(p);
  });

  const end = (ev) => {
    if (!press) return;
    const p = view.eventPixel(ev);
    const wasClick = !press.node && !press.moved && ev.type === 'pointerup' && st.mode !== 'tracking';
    if (press.draw) ctx.tracking.drawEnd(view.toMetre(p.x, p.y));
    press = null;
    canvas.classList.remove('dragging');
    if (wasClick && view.inPlot(p.x, p.y)) {
      const m = view.toMetre(p.x, p.y);
      ctx.placeTarget(m.x, m.y);
    }
  };
  canvas.addEventListener('pointerup', end);
  canvas.addEventListener('pointercancel', end);
  canvas.addEventListener('pointerleave', () => { if (!press) hover({ x: -1, y: -1 }); });
  return { showHint: () => hover({ x: -1, y: -1 }) };
}
