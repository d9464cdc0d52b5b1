// Keyboard on the plot (all three views). The canvas is focusable (tabindex=0); while it has the
// focus, Tab / Shift+Tab select the map's objects in turn (Tx, then Rx; in the multi-target view
// also the targets and discs) and leave the canvas after the last (or before the first), so the
// keyboard is never trapped. + and − zoom about the window's centre and 0 resets it (zoom.js).
// The arrow keys move the selected object by STEP_M (Shift:
// STEP_SHIFT_M) through the drag's own path (interact.js moveNode, mtl.js moveTo), so the map
// recomputes exactly as for a mouse drag; Delete (or Backspace) removes it through the panel's
// remove path (Panel.removeNode, Mtl.remove), where the core refuses the last node (its message
// in the error banner). A focus ring is drawn around the selected object while the canvas has
// keyboard focus (draw.js plotFocus); #kbd-status (aria-live) announces the selection.

import { $, fixed } from './dom.js';
import { plotFocus } from './draw.js';
import { moveNode } from './interact.js';

const STEP_M = 0.1;
const STEP_SHIFT_M = 1;
const ARROWS = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
/** A focus this soon after a press on the page came from the pointer (which selects itself), ms. */
const POINTER_FOCUS_MS = 500;

/** @param {object} ctx - {app, st, view, changed, panel, plan, zoom}; `mtl` the multi-target view. */
export function attachKeyboard(ctx, mtl) {
  const { app, st, view } = ctx;
  const canvas = view.canvas;
  const live = $('kbd-status');
  let lastPointer = -Infinity;
  let moving = false; // an arrow key is down (the map is reduced as in a drag until it is up)
  addEventListener('pointerdown', () => { lastPointer = performance.now(); }, true);

  const isMtl = () => st.mode === 'mtl';
  const at = (kind, list) => list.map((_, index) => ({ kind, index }));
  /** The selectable objects in Tab order. */
  const items = () => {
    if (isMtl()) {
      const s = mtl.scene;
      return [...at('tx', s.transmitters), ...at('rx', s.receivers), ...at('target', s.targets), ...at('disc', s.discs)];
    }
    const n = app.nodes();
    return [...at('tx', n.transmitters), ...at('rx', n.receivers)];
  };
  const current = () => (isMtl() ? mtl.selected : st.selected);
  /** {name, x, y} of a selection, or null if it no longer exists. */
  const describe = (sel) => {
    if (!sel) return null;
    if (isMtl()) {
      const q = mtl.scene[mtl.listOf(sel.kind)][sel.index];
      const prefix = { tx: 'Tx', rx: 'Rx', target: 'Target T', disc: 'Disc ' }[sel.kind];
      return q ? { name: `${prefix}${sel.index + 1}`, x: q[0], y: q[1] } : null;
    }
    const n = app.nodes();
    const q = (sel.kind === 'tx' ? n.transmitters : n.receivers)[sel.index];
    return q ? { name: q.name, x: q.x, y: q.y } : null;
  };
  const where = (d) => `(${fixed(d.x, 2)}, ${fixed(d.y, 2)}) m`;
  const announce = (text) => { live.textContent = text; };
  const redraw = () => ctx.changed(isMtl() ? { mtl: true } : { draw: true });

  const select = (sel) => {
    if (isMtl()) {
      mtl.selected = sel;
      redraw();
    } else {
      ctx.panel.select(sel.kind, sel.index);
    }
    const d = describe(sel);
    if (d) announce(`${d.name} selected at ${where(d)}`);
  };

  const setFocusRing = (on) => {
    if (plotFocus.on === on) return;
    plotFocus.on = on;
    redraw();
  };

  canvas.addEventListener('focus', (ev) => {
    setFocusRing(true);
    if (performance.now() - lastPointer < POINTER_FOCUS_MS) return; // the press selects
    const list = items();
    const from = ev.relatedTarget;
    if (!list.length || !from || from === canvas) return;
    // Entered backwards (Shift+Tab from a later control): the last object; else the first.
    const back = !!(canvas.compareDocumentPosition(from) & Node.DOCUMENT_POSITION_FOLLOWING);
    select(back ? list[list.length - 1] : list[0]);
  });
  canvas.addEventListener('blur', () => {
    setFocusRing(false);
    endMove();
  });

  /** The end of a keyboard move: the full map, as at a drag's end. */
  const endMove = () => {
    if (!moving) return;
    moving = false;
    if (!isMtl()) ctx.changed({ map: true, dragEnd: true });
  };

  const move = (sel, dx, dy) => {
    const d = describe(sel);
    if (!d) return;
    // The bounds of a drag (the region, the plotted area) hold here too; a node already outside
    // them (an imported scenario) is not pulled in.
    const [x0, x1, y0, y1] = isMtl() ? mtl.scene.region : app.area();
    const lim = (v, step, lo, hi) => (v >= lo && v <= hi ? Math.min(Math.max(v + step, lo), hi) : v + step);
    const x = lim(d.x, dx, x0, x1);
    const y = lim(d.y, dy, y0, y1);
    if (isMtl()) {
      mtl.moveTo(sel, x, y);
    } else {
      if (!moving && ctx.plan) ctx.plan.cancel('node moved');
      moving = true;
      moveNode(ctx, sel, x, y);
    }
    const e = describe(sel);
    if (e) announce(`${e.name} at ${where(e)}`);
  };

  const remove = (sel) => {
    const d = describe(sel);
    if (!d) return;
    let ok;
    if (isMtl()) {
      ok = mtl.remove(mtl.listOf(sel.kind), sel.kind);
    } else {
      ok = ctx.panel.removeNode(sel.kind);
    }
    if (!ok) {
      announce(`${d.name} not removed: ${$('error-text').textContent}`);
      return;
    }
    const list = items();
    const next = list.length ? (list.find((s) => s.kind === sel.kind && s.index === Math.max(0, sel.index - 1)) || list[0]) : null;
    if (next) select(next);
    const e = describe(next);
    announce(`${d.name} removed${e ? `; ${e.name} selected at ${where(e)}` : ''}`);
  };

  canvas.addEventListener('keydown', (ev) => {
    if (ev.ctrlKey || ev.altKey || ev.metaKey) return;
    setFocusRing(true);
    if (ev.key === 'Tab') {
      const list = items();
      const sel = current();
      const i = sel ? list.findIndex((s) => s.kind === sel.kind && s.index === sel.index) : -1;
      const next = i < 0 ? (ev.shiftKey ? list.length - 1 : 0) : i + (ev.shiftKey ? -1 : 1);
      if (next < 0 || next >= list.length) return; // leave the canvas
      ev.preventDefault();
      select(list[next]);
      return;
    }
    const sel = current();
    if (ARROWS[ev.key]) {
      ev.preventDefault();
      if (!sel) { const list = items(); if (list.length) select(list[0]); return; }
      const step = ev.shiftKey ? STEP_SHIFT_M : STEP_M;
      move(sel, ARROWS[ev.key][0] * step, ARROWS[ev.key][1] * step);
    } else if (ev.key === '+' || ev.key === '=' || ev.key === '-' || ev.key === '0') {
      ev.preventDefault();
      if (ev.key === '0') ctx.zoom.reset();
      else if (ev.key === '-') ctx.zoom.zoomOut();
      else ctx.zoom.zoomIn();
    } else if (ev.key === 'Delete' || ev.key === 'Backspace') {
      ev.preventDefault();
      if (sel) remove(sel);
    }
  });
  canvas.addEventListener('keyup', (ev) => {
    if (ARROWS[ev.key]) endMove();
  });
}
