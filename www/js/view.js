// Pixel <-> metre transform of the plot: DPR-aware canvas, equal scale on both axes (metres stay
// square), y up, and the window shown: the home extent (the scenario area, or the multi-target
// region) or a zoomed / panned part of it (zoom.js routes the gestures here). The only arithmetic
// in the page's JavaScript lives here.

import { fitCanvas } from './dom.js';

export const MARGIN = { left: 58, right: 112, top: 16, bottom: 44 };
/** The margins of a map canvas narrower than NARROW_PX (a phone): the colour bar kept tight. */
export const MARGIN_NARROW = { left: 50, right: 84, top: 16, bottom: 44 };
const NARROW_PX = 480;
/** Zoom limits: the window's width between these multiples of the home extent's width. */
export const ZOOM_SPAN = { min: 1e-4, max: 8 };
/** Rounding allowed on a shared window's limits, a fraction of the home extent's side. */
const SLACK = 1e-9;

export class View {
  /** @param {object} [margin] - the plot's margins, CSS px (default MARGIN: room for the colour bar). */
  constructor(canvas, margin = MARGIN) {
    this.canvas = canvas;
    this.margin = margin;
    this.dpr = 1;
    this.width = 1; // CSS px
    this.height = 1;
    this.area = [0, 1, 0, 1]; // the window shown: x_min, x_max, y_min, y_max (m)
    this.home = null; // the extent a reset returns to (same layout), or null before setHome
    this.scale = 1; // CSS px per metre
    this.rect = { x: 0, y: 0, w: 1, h: 1 }; // plot rectangle, CSS px
    this.drawn = { ticks: null, scaleBar: null }; // what the last frame drew from the window (draw.js)
  }

  /** Matches the backing store to the element size and device pixel ratio. */
  resize() {
    ({ width: this.width, height: this.height, dpr: this.dpr } = fitCanvas(this.canvas));
    this.fit(this.area);
  }

  /** Fits the area into the canvas with equal x/y scale, centred. */
  fit(area) {
    this.area = Array.from(area);
    const [x0, x1, y0, y1] = this.area;
    const M = this.margin === MARGIN && this.width < NARROW_PX ? MARGIN_NARROW : this.margin;
    const w = Math.max(10, this.width - M.left - M.right);
    const h = Math.max(10, this.height - M.top - M.bottom);
    this.scale = Math.min(w / (x1 - x0), h / (y1 - y0));
    const pw = this.scale * (x1 - x0);
    const ph = this.scale * (y1 - y0);
    this.rect = { x: M.left + (w - pw) / 2, y: M.top + (h - ph) / 2, w: pw, h: ph };
  }

  /**
   * The extent the window resets to. A new home (another scenario area or region) also resets
   * the window; the same home keeps a zoomed window.
   */
  setHome(extent) {
    const e = Array.from(extent);
    if (this.home && e.every((v, i) => v === this.home[i])) return;
    this.home = e;
    this.fit(e);
  }

  /**
   * Where a window's centre may be: the home extent grown by its own size on each side
   * ([x_lo, x_hi, y_lo, y_hi] m), the limit of a pan (panBy) and of a shared window (setWindow).
   */
  reach() {
    const [hx0, hx1, hy0, hy1] = this.home;
    return [hx0 - (hx1 - hx0), hx1 + (hx1 - hx0), hy0 - (hy1 - hy0), hy1 + (hy1 - hy0)];
  }

  /**
   * Shows the window `w` = [x0, x1, y0, y1] m (a shared link's, already checked by the core's
   * rule for areas, check_rect) if a zoom and pan could show it: each side within ZOOM_SPAN of
   * the home's and its centre within reach(); otherwise throws naming what is wrong and the
   * allowed range, and changes nothing.
   */
  setWindow(w) {
    const [x0, x1, y0, y1] = w;
    if (!w.every(Number.isFinite) || !(x1 > x0) || !(y1 > y0)) {
      throw new Error(`"${w.join(',')}" is not a window x0,x1,y0,y1 with x0 < x1 and y0 < y1`);
    }
    const [hx0, hx1, hy0, hy1] = this.home;
    const [rx0, rx1, ry0, ry1] = this.reach();
    for (const [axis, lo, hi, hlo, hhi, clo, chi] of [['x', x0, x1, hx0, hx1, rx0, rx1], ['y', y0, y1, hy0, hy1, ry0, ry1]]) {
      const span = hi - lo;
      const home = hhi - hlo;
      // SLACK: a window the gestures made (clamped to a limit, then rounded) is always accepted.
      const slack = SLACK * home;
      if (!(span >= ZOOM_SPAN.min * home - slack && span <= ZOOM_SPAN.max * home + slack)) {
        throw new Error(`the window's ${axis} side of ${span} m is outside ${ZOOM_SPAN.min} … ${ZOOM_SPAN.max} times `
          + `the area's ${home} m (allowed ${ZOOM_SPAN.min * home} … ${ZOOM_SPAN.max * home} m)`);
      }
      const c = (lo + hi) / 2;
      if (!(c >= clo - slack && c <= chi + slack)) {
        throw new Error(`the window's ${axis} centre ${c} m is outside ${clo} … ${chi} m (the area grown by its size on each side)`);
      }
    }
    this.fit(w);
  }

  /** Back to the home extent. */
  reset() {
    if (this.home) this.fit(this.home);
  }

  /** True when the window is not the home extent. */
  zoomed() {
    return !!this.home && this.area.some((v, i) => v !== this.home[i]);
  }

  /** Magnification of the window against the home extent (1: the whole of it). */
  zoomFactor() {
    return this.home ? (this.home[1] - this.home[0]) / (this.area[1] - this.area[0]) : 1;
  }

  /**
   * Zooms by `factor` (< 1: in; the window's width times factor, within ZOOM_SPAN of the home's)
   * about the canvas pixel (px, py), whose metre point stays under it. Returns the factor applied.
   */
  zoomAt(px, py, factor) {
    if (!this.home || !(factor > 0) || !Number.isFinite(factor)) return 1;
    const [x0, x1, y0, y1] = this.area;
    const homeW = this.home[1] - this.home[0];
    const w = Math.min(Math.max((x1 - x0) * factor, ZOOM_SPAN.min * homeW), ZOOM_SPAN.max * homeW);
    const f = w / (x1 - x0);
    if (f === 1) return 1;
    const m = this.toMetre(px, py);
    // The window of the home (f applied to the home's own numbers) lands exactly on the home.
    const back = Math.abs(w - homeW) <= 1e-9 * homeW;
    this.fit(back ? this.home : [m.x + (x0 - m.x) * f, m.x + (x1 - m.x) * f, m.y + (y0 - m.y) * f, m.y + (y1 - m.y) * f]);
    return f;
  }

  /**
   * Moves the window by (dx, dy) CSS px of drag (the map follows the pointer); its centre stays
   * within the home extent grown by its own size on each side.
   */
  panBy(dx, dy) {
    if (!this.home) return;
    const [x0, x1, y0, y1] = this.area;
    const [rx0, rx1, ry0, ry1] = this.reach();
    const clampShift = (shift, lo, hi, clo, chi) => {
      const c = (lo + hi) / 2 + shift;
      return Math.min(Math.max(c, clo), chi) - (lo + hi) / 2;
    };
    const sx = clampShift(-dx / this.scale, x0, x1, rx0, rx1);
    const sy = clampShift(dy / this.scale, y0, y1, ry0, ry1);
    if (sx === 0 && sy === 0) return;
    this.fit([x0 + sx, x1 + sx, y0 + sy, y1 + sy]);
  }

  /**
   * The pixel box ({a: top left, b: bottom right}) a node drag stays in: the home extent where it
   * is in sight, else the home extent itself.
   */
  dragBox() {
    const r = this.rect;
    const [x0, x1, y0, y1] = this.home || this.area;
    const a = this.toPixel(x0, y1);
    const b = this.toPixel(x1, y0);
    const box = {
      a: { x: Math.max(a.x, r.x), y: Math.max(a.y, r.y) },
      b: { x: Math.min(b.x, r.x + r.w), y: Math.min(b.y, r.y + r.h) },
    };
    return box.a.x <= box.b.x && box.a.y <= box.b.y ? box : { a, b };
  }

  /** Metres -> CSS pixels relative to the canvas' top-left corner. */
  toPixel(x, y) {
    return { x: this.rect.x + (x - this.area[0]) * this.scale, y: this.rect.y + (this.area[3] - y) * this.scale };
  }

  /** CSS pixels (canvas-relative) -> metres. */
  toMetre(px, py) {
    return { x: this.area[0] + (px - this.rect.x) / this.scale, y: this.area[3] - (py - this.rect.y) / this.scale };
  }

  /** CSS pixels -> metres, the pixel first clamped into the box from corner `a` (top left) to `b`. */
  toMetreWithin(p, a, b) {
    return this.toMetre(Math.min(Math.max(p.x, a.x), b.x), Math.min(Math.max(p.y, a.y), b.y));
  }

  /**
   * The part of the segment from pixel `a` to pixel `b` inside the plot rectangle (Liang–Barsky),
   * [a', b'] ({x, y} CSS px), or null when it misses the plot.
   */
  clipSegment(a, b) {
    const r = this.rect;
    const dx = b.x - a.x;
    const dy = b.y - a.y;
    let t0 = 0;
    let t1 = 1;
    for (const [p, q] of [[-dx, a.x - r.x], [dx, r.x + r.w - a.x], [-dy, a.y - r.y], [dy, r.y + r.h - a.y]]) {
      if (p === 0) {
        if (q < 0) return null;
      } else if (p < 0) t0 = Math.max(t0, q / p);
      else t1 = Math.min(t1, q / p);
    }
    if (t0 > t1) return null;
    return [{ x: a.x + t0 * dx, y: a.y + t0 * dy }, { x: a.x + t1 * dx, y: a.y + t1 * dy }];
  }

  /** A length in metres as CSS pixels. */
  len(m) {
    return m * this.scale;
  }

  /** True if the CSS pixel lies in the plot rectangle. */
  inPlot(px, py) {
    const r = this.rect;
    return px >= r.x && px <= r.x + r.w && py >= r.y && py <= r.y + r.h;
  }

  /** 2-D context drawing in CSS pixels. */
  context() {
    const ctx = this.canvas.getContext('2d');
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    return ctx;
  }

  /**
   * Fills every pixel of the backing store with `color`. (A fill of the CSS size only blends into
   * the last row or column when that size is fractional, so redraws would pile up there.)
   */
  clear(ctx, color) {
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = color;
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    ctx.restore();
  }

  /** Event -> canvas-relative CSS pixels. */
  eventPixel(ev) {
    const r = this.canvas.getBoundingClientRect();
    return { x: ev.clientX - r.left, y: ev.clientY - r.top };
  }
}

/**
 * A zoom window: `size` CSS px square at (x, y) showing `radius` metres around `center` (m).
 * Same conventions as View (y up).
 */
export class Zoom {
  constructor(x, y, size, center, radius) {
    this.rect = { x, y, w: size, h: size };
    this.center = center;
    this.scale = (size / 2) / radius;
  }

  toPixel(x, y) {
    return {
      x: this.rect.x + this.rect.w / 2 + (x - this.center.x) * this.scale,
      y: this.rect.y + this.rect.h / 2 - (y - this.center.y) * this.scale,
    };
  }

  len(m) {
    return m * this.scale;
  }
}
