// The zoom inset around the target (the snapshot view's target zoom, the tracking view's true-
// scale zoom): where it goes and its controls. Placed automatically, it keeps clear of the target,
// every node and the track (the candidate box covering the least weight of the view's avoid
// points, shrunk if no full-size box is free); its header can be dragged (or moved with the arrow
// keys) to put it anywhere on the canvas, and its × button closes it ("Show zoom inset" brings it
// back, where it was placed automatically). The drawing is map.js's drawInset.

import { $ } from './dom.js';

/** Weight of a point the inset must never cover (the target, a node). */
export const HARD = 1e6;
/** Smallest inset side, CSS px. */
const MIN_SIZE = 80;
/** Height of the inset's header strip (the drag handle and the × button), CSS px. */
export const HEAD_PX = 24;
/** Keyboard move of the inset, CSS px (Shift: ×5). */
const KEY_STEP = 10;
/** The × button's width (CSS px; style.css .inset-close) while it is not laid out. */
const CLOSE_PX = 24;

/**
 * The box {x, y, size} (CSS px) of an inset of side `size` inside the plot rectangle `r` that
 * covers the least weight of `points` ([{x, y, w, m}]: canvas px, weight, margin px), the first
 * in order on ties (the four corners first, then the edge midpoints, then a grid); smaller boxes
 * (down to MIN_SIZE) are tried when every box of a size covers a hard point. Null if none fits.
 */
export function chooseBox(r, size, points, pad = 10) {
  const inside = (b, p) => p.x > b.x - p.m && p.x < b.x + b.size + p.m && p.y > b.y - p.m && p.y < b.y + b.size + p.m;
  const cost = (b) => points.reduce((sum, p) => sum + (inside(b, p) ? p.w : 0), 0);
  let best = null;
  for (let s = size; s >= MIN_SIZE; s = Math.floor(s * 0.8)) {
    const xs = [r.x + r.w - s - pad, r.x + pad];
    const ys = [r.y + pad, r.y + r.h - s - pad];
    if (xs[0] < xs[1] || ys[1] < ys[0]) continue;
    const cands = [
      { x: xs[0], y: ys[0] }, { x: xs[1], y: ys[0] }, { x: xs[0], y: ys[1] }, { x: xs[1], y: ys[1] },
      { x: (xs[0] + xs[1]) / 2, y: ys[0] }, { x: (xs[0] + xs[1]) / 2, y: ys[1] },
      { x: xs[0], y: (ys[0] + ys[1]) / 2 }, { x: xs[1], y: (ys[0] + ys[1]) / 2 },
    ];
    const steps = 6;
    for (let i = 0; i <= steps; i++) {
      for (let j = 0; j <= steps; j++) {
        cands.push({ x: xs[1] + ((xs[0] - xs[1]) * i) / steps, y: ys[0] + ((ys[1] - ys[0]) * j) / steps });
      }
    }
    for (const c of cands) {
      const b = { x: c.x, y: c.y, size: s };
      const k = cost(b);
      if (!best || k < best.cost) best = { ...b, cost: k };
    }
    if (best && best.cost < HARD) break;
  }
  return best;
}

export class InsetControls {
  /**
   * @param {HTMLCanvasElement} canvas - the map canvas (its parent holds the controls).
   * @param {function} redraw - asks for a redraw.
   */
  constructor(canvas, redraw) {
    this.canvas = canvas;
    this.redraw = redraw;
    this.closed = false;
    this.pos = null; // {x, y}: the box's top left placed by the user (CSS px), or null (automatic)
    this.box = null; // the box of the last frame {x, y, size, auto} or null (none drawn)
    const wrap = canvas.parentElement;
    const head = document.createElement('div');
    head.className = 'inset-head';
    head.hidden = true;
    const grip = document.createElement('button');
    grip.type = 'button';
    grip.className = 'inset-grip';
    grip.setAttribute('aria-label', 'Move the zoom inset: drag it, or use the arrow keys');
    grip.title = 'Drag to move the zoom inset (arrow keys: 10 px, Shift: 50 px)';
    const close = document.createElement('button');
    close.type = 'button';
    close.className = 'inset-close';
    close.setAttribute('aria-label', 'Close the zoom inset');
    close.title = 'Close the zoom inset';
    close.textContent = '×';
    head.append(grip, close);
    const open = document.createElement('button');
    open.type = 'button';
    open.id = 'inset-open';
    open.className = 'small inset-open';
    open.hidden = true;
    open.textContent = 'Show zoom inset';
    open.title = 'Show the zoom inset around the target again';
    wrap.append(head, open);
    Object.assign(this, { head, grip, closeButton: close, openButton: open });
    close.addEventListener('click', () => this.setClosed(true));
    open.addEventListener('click', () => this.setClosed(false));
    this.attachDrag();
    // A wheel or pinch over the header zooms the map under it, as anywhere else on the map.
    head.addEventListener('wheel', (ev) => {
      ev.preventDefault();
      canvas.dispatchEvent(new WheelEvent('wheel', ev));
    }, { passive: false });
    grip.addEventListener('keydown', (ev) => {
      const d = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] }[ev.key];
      if (!d || !this.box) return;
      ev.preventDefault();
      const k = KEY_STEP * (ev.shiftKey ? 5 : 1);
      this.moveTo(this.box.x + d[0] * k, this.box.y + d[1] * k);
    });
  }

  /** Closes (true) or reopens (false) the inset; reopened, it is placed automatically again. */
  setClosed(on) {
    this.closed = !!on;
    if (!on) this.pos = null;
    this.redraw();
    (on ? this.openButton : this.grip).focus({ preventScroll: true });
  }

  /** Puts the box's top left at (x, y) CSS px, kept on the canvas. */
  moveTo(x, y) {
    const size = this.box ? this.box.size : MIN_SIZE;
    const w = this.canvas.clientWidth;
    const h = this.canvas.clientHeight;
    this.pos = { x: Math.min(Math.max(0, x), Math.max(0, w - size)), y: Math.min(Math.max(0, y), Math.max(0, h - size)) };
    this.redraw();
  }

  attachDrag() {
    let drag = null;
    this.grip.addEventListener('pointerdown', (ev) => {
      if (ev.button !== 0 || !this.box) return;
      ev.preventDefault();
      this.grip.setPointerCapture(ev.pointerId);
      drag = { x: ev.clientX, y: ev.clientY, bx: this.box.x, by: this.box.y };
    });
    this.grip.addEventListener('pointermove', (ev) => {
      if (!drag) return;
      this.moveTo(drag.bx + ev.clientX - drag.x, drag.by + ev.clientY - drag.y);
    });
    const end = () => { drag = null; };
    this.grip.addEventListener('pointerup', end);
    this.grip.addEventListener('pointercancel', end);
  }

  /**
   * The box to draw: the user's position (kept on the canvas) at `size`, or `auto()` (the
   * automatic choice); null when closed.
   */
  place(size, auto) {
    if (this.closed) return null;
    if (!this.pos) return auto();
    const w = this.canvas.clientWidth;
    const h = this.canvas.clientHeight;
    return {
      x: Math.min(Math.max(0, this.pos.x), Math.max(0, w - size)),
      y: Math.min(Math.max(0, this.pos.y), Math.max(0, h - size)),
      size,
      moved: true,
    };
  }

  /** The width (CSS px) the title of an inset of side `size` may take: left of the × with a gap. */
  titleRoom(size) {
    return size - 8 - (this.closeButton.offsetWidth || CLOSE_PX) - 6;
  }

  /**
   * After a frame: the controls over the box drawn (or hidden when none; "Show" when closed);
   * the header's name and tooltip carry the inset's full title (cut on the canvas if long).
   */
  shown(box, hasTarget) {
    this.box = box;
    const head = this.head;
    head.hidden = !box;
    this.openButton.hidden = !(this.closed && hasTarget);
    if (!box) return;
    Object.assign(head.style, { left: `${box.x}px`, top: `${box.y}px`, width: `${box.size}px`, height: `${HEAD_PX}px` });
    const name = box.title ? `${box.title.full}: m` : 'M';
    this.grip.setAttribute('aria-label', `${name}ove the zoom inset: drag it, or use the arrow keys`);
    this.grip.title = `${box.title ? `${box.title.full}: d` : 'D'}rag to move the zoom inset (arrow keys: 10 px, Shift: 50 px)`;
  }

  /**
   * For the hooks: {closed, moved, box: {x, y, size} | null, colors: {bg, title, halo} | null,
   * title: {text, full, box: {x, y, w, h}} | null} (the CSS colours the last frame drew the
   * inset's background, title and title halo in; the title drawn, cut or not, and its ink box).
   */
  state() {
    const b = this.box;
    return {
      closed: this.closed,
      moved: !!this.pos,
      box: b ? { x: b.x, y: b.y, size: b.size } : null,
      colors: b && b.colors ? { ...b.colors } : null,
      title: b && b.title ? { ...b.title, box: { ...b.title.box } } : null,
    };
  }
}

/** The element of the inset's controls (for tests' clicks): 'grip' | 'close' | 'open'. */
export function insetControl(which) {
  return which === 'open' ? $('inset-open') : document.querySelector(which === 'close' ? '.inset-close' : '.inset-grip');
}
