// Pixel <-> metre transform of the plot: DPR-aware canvas, equal scale on both axes (metres stay
// square), y up. The only arithmetic in the page's JavaScript lives here.

import { fitCanvas } from './dom.js';

export const MARGIN = { left: 58, right: 112, top: 16, bottom: 44 };

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.dpr = 1;
    this.width = 1; // CSS px
    this.height = 1;
    this.area = [0, 1, 0, 1]; // x_min, x_max, y_min, y_max (m)
    this.scale = 1; // CSS px per metre
    this.rect = { x: 0, y: 0, w: 1, h: 1 }; // plot rectangle, CSS px
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
    const w = Math.max(10, this.width - MARGIN.left - MARGIN.right);
    const h = Math.max(10, this.height - MARGIN.top - MARGIN.bottom);
    this.scale = Math.min(w / (x1 - x0), h / (y1 - y0));
    const pw = this.scale * (x1 - x0);
    const ph = this.scale * (y1 - y0);
    this.rect = { x: MARGIN.left + (w - pw) / 2, y: MARGIN.top + (h - ph) / 2, w: pw, h: ph };
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
