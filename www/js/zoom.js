// Zoom and pan of the plot in the three views. The window lives in the view on
// screen (view.js: zoomAt, panBy, reset); this file routes the gestures to it:
//   wheel (and a trackpad pinch, which Chromium sends as ctrl+wheel)   zoom about the cursor
//   two fingers on the plot    pinch zoom about their midpoint, panning with it
//   press and drag on empty map    pan (the press handlers of interact.js and mtl.js call panBy
//                                  and settle, so a press on a node still drags the node)
//   double-click on empty map, #zoom-reset, key 0    back to the home extent
//   #zoom-in, #zoom-out, keys + and − (keyboard.js)   zoom about the window's centre
// The snapshot and tracking views then recompute the CRLB map for the new window at the chosen
// grid (map.js; while a gesture goes on at the drag's reduced resolution, in full at its end), so
// zooming in shows finer detail, not bigger pixels; the axes, the scale bar and the colour bar are
// drawn from the window and the new map. The multi-target view redraws its region.

import { $ } from './dom.js';
import { homeWithNodes } from './outside.js';
import { mtlHome } from './mtl.js';
import { registerSection } from './state.js';
import { checkWindow, fields, flag, number } from './state-fields.js';

/** Wheel travel (CSS px) that zooms by a factor of 2 (a mouse notch is about 100 px: ×1.26). */
const WHEEL_PX_PER_DOUBLING = 300;
/** Factor of one button press or key press. */
const STEP = 1.5;

export class Zoomer {
  /**
   * @param {object} ctx - {st, view, changed}; `mtl` the multi-target view (its own View);
   *   `hitAt(p)`: whether an object of the view on screen lies under canvas pixel p.
   */
  constructor(ctx, mtl, hitAt) {
    this.ctx = ctx;
    this.mtl = mtl;
    this.hitAt = hitAt;
    this.cancelPress = []; // the press handlers' cancel functions (a second finger ends a drag)
    this.fingers = new Map(); // pointerId -> canvas pixel, of pointers down on the plot
    this.pinch = null; // {dist, mid} of the last pinch step
    this.gestures = 0; // zoom and pan steps so far (hook)
    const canvas = ctx.view.canvas;
    this.canvas = canvas;
    canvas.addEventListener('wheel', (ev) => this.wheel(ev), { passive: false });
    this.onFit = []; // called after a double-click fitted the zoom (interact.js: no target placed)
    canvas.addEventListener('dblclick', (ev) => {
      const p = this.view().eventPixel(ev);
      if (this.view().inPlot(p.x, p.y) && !this.hitAt(p) && this.view().zoomed()) {
        this.reset();
        for (const f of this.onFit) f();
      }
    });
    // Document capture: the pinch sees the pointers before interact.js and mtl.js do.
    document.addEventListener('pointerdown', (ev) => this.down(ev), true);
    document.addEventListener('pointermove', (ev) => this.move(ev), true);
    document.addEventListener('pointerup', (ev) => this.up(ev), true);
    document.addEventListener('pointercancel', (ev) => this.up(ev), true);
    $('zoom-in').addEventListener('click', () => this.zoomIn());
    $('zoom-out').addEventListener('click', () => this.zoomOut());
    $('zoom-reset').addEventListener('click', () => this.reset());
    this.show();
  }

  /** The view on screen: the multi-target view's own, or the map's. */
  view() {
    return this.ctx.st.mode === 'mtl' ? this.mtl.view : this.ctx.view;
  }

  /**
   * The window changed: redraw, and (snapshot, tracking) recompute the map, reduced while `live`
   * (a pan or pinch going on), in full otherwise.
   */
  changed(live) {
    this.gestures += 1;
    this.show();
    if (this.ctx.st.mode === 'mtl') this.ctx.changed({ mtl: true });
    else this.ctx.changed(live ? { map: true, dragging: true } : { map: true, dragEnd: true });
  }

  /** A pan or pinch ended: the map in full. */
  settle() {
    this.changed(false);
  }

  /** Moves the window by a drag of (dx, dy) CSS px (a press on empty map). */
  panBy(dx, dy) {
    this.view().panBy(dx, dy);
    this.changed(true);
  }

  /** Zooms by `factor` about the window's centre (buttons, keys). */
  step(factor) {
    const r = this.view().rect;
    if (this.view().zoomAt(r.x + r.w / 2, r.y + r.h / 2, factor) !== 1) this.changed(false);
  }

  zoomIn() {
    this.step(1 / STEP);
  }

  zoomOut() {
    this.step(STEP);
  }

  /** Back to the home extent (the scenario area, the multi-target region). */
  reset() {
    if (!this.view().zoomed()) return;
    this.view().reset();
    this.changed(false);
  }

  wheel(ev) {
    const view = this.view();
    const p = view.eventPixel(ev);
    if (!view.inPlot(p.x, p.y)) return; // the page scrolls
    ev.preventDefault();
    const px = ev.deltaY * (ev.deltaMode === 1 ? 16 : ev.deltaMode === 2 ? view.height : 1);
    if (view.zoomAt(p.x, p.y, 2 ** (px / WHEEL_PX_PER_DOUBLING)) !== 1) this.changed(false);
  }

  down(ev) {
    if (ev.target !== this.canvas || (ev.pointerType === 'mouse' && ev.button !== 0)) return;
    this.fingers.set(ev.pointerId, this.view().eventPixel(ev));
    if (this.fingers.size < 2) return;
    ev.stopPropagation();
    ev.preventDefault();
    this.canvas.setPointerCapture(ev.pointerId);
    if (!this.pinch) {
      for (const cancel of this.cancelPress) cancel();
      this.pinch = this.spread();
    }
  }

  move(ev) {
    if (!this.fingers.has(ev.pointerId)) return;
    this.fingers.set(ev.pointerId, this.view().eventPixel(ev));
    if (!this.pinch) return;
    ev.stopPropagation();
    const now = this.spread();
    const view = this.view();
    view.zoomAt(this.pinch.mid.x, this.pinch.mid.y, this.pinch.dist / Math.max(now.dist, 1));
    view.panBy(now.mid.x - this.pinch.mid.x, now.mid.y - this.pinch.mid.y);
    this.pinch = now;
    this.changed(true);
  }

  up(ev) {
    if (!this.fingers.delete(ev.pointerId)) return;
    if (!this.pinch) return;
    ev.stopPropagation();
    if (this.fingers.size < 2) {
      this.pinch = null;
      this.settle();
    }
  }

  /** Distance and midpoint of the first two fingers, CSS px. */
  spread() {
    const [a, b] = [...this.fingers.values()];
    return { dist: Math.hypot(a.x - b.x, a.y - b.y), mid: { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 } };
  }

  /** #zoom-level and the reset button's state. */
  show() {
    const view = this.view();
    const z = view.zoomFactor();
    const el = $('zoom-level');
    el.textContent = view.zoomed() ? `×${z >= 10 ? Math.round(z) : z.toFixed(z >= 1 ? 1 : 2)}` : 'fit';
    el.dataset.factor = String(z);
    $('zoom-reset').disabled = !view.zoomed();
  }

  /** Hook: the window of the view on screen. */
  state() {
    const view = this.view();
    return {
      window: Array.from(view.area), home: view.home ? Array.from(view.home) : null,
      zoomed: view.zoomed(), factor: view.zoomFactor(), rect: { ...view.rect }, gestures: this.gestures,
      ticks: view.drawn.ticks, scaleBar: view.drawn.scaleBar, level: $('zoom-level').textContent,
    };
  }
}

/**
 * Registers the page state's `view` section (not in the undo history): the map's and the
 * multi-target view's zoomed windows, whether the Plan panel is open and the tracking step.
 * The windows are checked against the homes of the scenario and scene being restored
 * (`pending.home`, `pending.region`) or, without them, the ones shown.
 * @param {object} p - {app, wasm, st, view, mtl, plan, tracking, zoom, ctx (ctx.changed),
 *   homeFor (app.js setHomeFor)}
 */
export function registerViewState({ app, wasm, st, view, mtl, plan, tracking, zoom, ctx, homeFor }) {
  const stepRange = JSON.parse(wasm.track_field_ranges()).step;
  registerSection('view', {
    history: false,
    get: () => ({
      map: view.zoomed() ? Array.from(view.area) : null,
      mtl: mtl.view.home && mtl.view.zoomed() ? Array.from(mtl.view.area) : null,
      plan_open: plan.open,
      step: tracking.track ? tracking.step : (tracking.startStep ?? 0),
    }),
    check: (v, pending) => {
      fields(v, 'state.view', ['map', 'mtl', 'plan_open', 'step']);
      const home = pending.home ?? homeWithNodes(Array.from(app.area()), app.nodes()).home;
      if (v.map !== null) checkWindow(v.map, 'state.view.map', home);
      if (v.mtl !== null) checkWindow(v.mtl, 'state.view.mtl', mtlHome(pending.region ?? mtl.scene.region));
      flag(v.plan_open, 'state.view.plan_open');
      number(v.step, 'state.view.step', { min: stepRange[0], max: stepRange[1], integer: true });
    },
    apply: (v) => {
      homeFor();
      if (v.map) view.setWindow(v.map); else view.reset();
      mtl.view.setHome(mtlHome(mtl.scene.region));
      if (v.mtl) mtl.view.setWindow(v.mtl); else mtl.view.reset();
      if (plan.open !== v.plan_open) plan.setOpen(v.plan_open);
      if (tracking.active() && tracking.track) tracking.seek(v.step);
      else tracking.startStep = v.step;
      zoom.show();
      ctx.changed(st.mode === 'mtl' ? { mtl: true } : { map: true });
    },
  });
}
