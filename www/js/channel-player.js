// The channel view's player (a part of the Channel class, channel.js): the time cursor (the
// slider, Play and its speed), the read-outs of the cursor's snapshot, the map layer (the
// segments up to the cursor, the ellipses, the links, the 1σ: channel-draw.js; several people's
// labelled tracks: people-draw.js), the delay and
// error charts drawn by the core's chart code with the cursor over them, and Save.

import { $, clip, errorText, fillKeyValues, fitCanvas, fixed, showError } from './dom.js';
import { drawChannel, drawCursor, drawSegments, lossName } from './channel-draw.js';
import { slug } from './export.js';
import { drawPeople, peopleColour } from './people-draw.js';

/** The read-out rows of several people at snapshot `k`: each reported track, then the people. */
function peopleRows(doc, k) {
  const step = Math.min(k, doc.track.t_s.length - 1);
  const rows = doc.track.targets[step].map((t, i) => {
    const e = doc.ellipses[step][i];
    return [`Track #${t.label}`, `${fixed(t.state[0], 3)}, ${fixed(t.state[1], 3)} m · 1σ ${e ? `${fixed(e.a, 3)} × ${fixed(e.b, 3)} m` : '—'}`, 'fix'];
  });
  if (!rows.length) rows.push(['Tracks', 'none reported', '']);
  rows.push(['Labelled tracks', String(doc.track.tracks.length), '']);
  if (doc.truth) rows.push(['True people', String(doc.truth.targets[step].length), '']);
  if (doc.score) rows.push([`GOSPA (c = ${fixed(doc.score.c_m, 2)} m)`, `${fixed(doc.score.gospa_m[step], 3)} m`, '']);
  return rows;
}

/** The player part of the Channel class (channel.js mixes it in). */
export const channelPlayer = {
  /** The transport (Play, the slider, the speed), the link shown, Save and the charts' resizing. */
  bindPlayer() {
    $('chan-speed').addEventListener('change', () => {
      this.s = { ...this.s, speed: Number($('chan-speed').value) };
    });
    $('chan-link').addEventListener('change', () => {
      this.s = { ...this.s, link: Number($('chan-link').value) };
      this.drawCharts();
    });
    $('chan-play').addEventListener('click', () => (this.playing ? this.pause() : this.play()));
    $('chan-scrub').addEventListener('input', () => {
      const n = Number($('chan-scrub').value); // before pause() redraws the transport (and the slider)
      this.pause();
      this.seek(n);
    });
    $('chan-save').addEventListener('click', () => this.save($('chan-save-what').value));
    const redrawCharts = () => { if (this.active()) this.drawCharts(); };
    new ResizeObserver(redrawCharts).observe($('chan-delays').parentElement);
    new ResizeObserver(redrawCharts).observe($('chan-errors').parentElement);
  },

  /** The result's number of snapshots (0 without one). */
  steps() { return this.result ? this.result.track.t_s.length : 0; },

  /** The overlay of snapshot k (cached). */
  overlay(k) {
    if (!this.fig) return null;
    if (!this.overlays.has(k)) this.overlays.set(k, this.fig.overlay(k));
    return this.overlays.get(k);
  },

  /** Moves the cursor to snapshot n (clamped): map, read-outs, chart cursors. */
  seek(n) {
    if (!this.result) return;
    this.hideReplay();
    this.step = Math.max(0, Math.min(Math.round(n), this.steps() - 1));
    this.pos = this.result.track.t_s[this.step];
    this.show();
    this.drawCursors();
    this.redraw();
  },

  /** Asks for the map's redraw (its channel layer). */
  redraw() { this.ctx.changed({ frame: true }); },

  /** Plays from the cursor (from the start when at the end) at the chosen speed. */
  play() {
    if (!this.result) return;
    this.hideReplay();
    if (this.step >= this.steps() - 1) this.seek(0);
    this.playing = true;
    this.pos = this.result.track.t_s[this.step];
    this.last = performance.now();
    requestAnimationFrame(this.tickFn);
    this.show();
  },

  /** Stops playing; the cursor stays. */
  pause() {
    if (!this.playing) return;
    this.playing = false;
    this.show();
  },

  /** One animation frame of playing: the cursor follows the time played. */
  tick(now) {
    if (!this.playing || !this.result) return;
    const t = this.result.track.t_s;
    this.pos += ((now - this.last) / 1000) * this.s.speed;
    this.last = now;
    let n = this.step;
    while (n + 1 < t.length && t[n + 1] <= this.pos) n += 1;
    if (n >= t.length - 1) this.playing = false;
    if (n !== this.step) {
      this.step = n;
      this.show();
      this.drawCursors();
      this.redraw();
    } else {
      this.show();
    }
    if (this.playing) requestAnimationFrame(this.tickFn);
  },

  /** The transport and the read-outs of the cursor's snapshot. */
  show() {
    $('chan-play').textContent = this.playing ? '❚❚ Pause' : '▶ Play';
    $('chan-play').dataset.playing = this.playing ? '1' : '0';
    if (!this.result) return;
    const tr = this.result.track;
    const n = this.steps() - 1;
    $('chan-scrub').value = String(this.step);
    $('chan-scrub').setAttribute('aria-valuetext', `t = ${fixed(tr.t_s[this.step], 2)} s, snapshot ${this.step} of ${n}`);
    const time = $('chan-time');
    time.textContent = `t = ${fixed(tr.t_s[this.step], 2)} s / ${fixed(tr.t_s[n], 2)} s · snapshot ${this.step}/${n}`;
    Object.assign(time.dataset, { step: String(this.step), t: String(tr.t_s[this.step]) });
    const ov = this.overlay(this.step);
    const m2 = (p) => (p ? `${fixed(p[0], 3)}, ${fixed(p[1], 3)} m` : '—');
    const truth = this.truthAt(this.step);
    const e = ov.sigma_ellipse;
    const seg = this.segmentAt(this.step);
    const people = this.result.people;
    if (people) {
      fillKeyValues($('chan-info'), peopleRows(people, this.step));
      return;
    }
    const rows = [
      [`${(tr.filter || this.result.settings.filter).toUpperCase()} estimate`, ov.state ? m2(ov.state) : seg.text, 'fix'],
      ['Segment', ov.segment === null || ov.segment === undefined ? '—'
        : `${ov.segment + 1} of ${tr.segments.length} (${fixed(tr.segments[ov.segment].t_first_s, 2)}–${fixed(tr.segments[ov.segment].t_last_s, 2)} s)`, ''],
      ['1σ ellipse', e ? `${fixed(e.a, 3)} × ${fixed(e.b, 3)} m` : '—', 'fix'],
      ['Truth', m2(truth), ''],
      ['Error', ov.error_m === null || ov.error_m === undefined ? '—' : `${fixed(ov.error_m, 3)} m`, 'fix'],
      ['Links used', ov.links.length ? ov.links.map((l) => this.result.names[l.link] || `link ${l.link}`).join(', ') : 'none', ''],
    ];
    fillKeyValues($('chan-info'), rows);
  },

  /**
   * What the track is doing at snapshot k outside its segments: {text} ("searching (not started
   * yet)", "lost at 7.35 s (outside area) · searching", "ended").
   */
  segmentAt(k) {
    const tr = this.result.track;
    const segs = tr.segments || [];
    const before = segs.filter((g) => g.last < k);
    if (!before.length) return { text: segs.length ? 'searching (not started yet)' : 'never started' };
    const g = before[before.length - 1];
    const t = tr.t_s[Math.min(g.last + 1, tr.t_s.length - 1)];
    return { text: g.end === 'end' ? 'ended' : `lost at ${fixed(t, 2)} s (${lossName(g.end)}) · searching` };
  },

  /** The true position at snapshot k ([x, y]) when a truth file of the run is at hand. */
  truthAt(k) {
    if (!this.truth || !this.result || this.truth.text !== this.result.truthText) return null;
    const s = this.truth.data.states[k];
    return s ? [s[0], s[1]] : null;
  },

  /** The map layer (app.js sets it as the scene's overlay in this view). */
  overlayLayer(ctx, view) {
    // A replay shown (running, or ended and not yet dismissed by the cursor): its states.
    if (this.replay && this.replay.show) {
      this.drawn = this.drawReplay(ctx, view);
      return;
    }
    if (!this.result) {
      this.drawn = null;
      return;
    }
    // A node moved (or the scenario changed) since the run: say so before drawing it stale.
    this.showStale(true);
    const people = this.result.people;
    if (people) {
      // Several people: every labelled track with its label and 1σ ellipse, and the true paths.
      const stale = this.stale.length > 0;
      if (stale) ctx.globalAlpha = 0.45;
      this.peopleLayer = drawPeople(ctx, view, people, this.step, 1, (label) => peopleColour(people, label));
      ctx.globalAlpha = 1;
      const l = this.peopleLayer;
      this.drawn = { step: this.step, people: l.tracks.length, labels: l.tracks.map((t) => t.label), truth_paths: l.truth.length, stale };
      return;
    }
    this.peopleLayer = null;
    const truth = this.truthAt(0) ? this.truth.data.states.map((s) => [s[0], s[1]]) : null;
    this.drawn = drawChannel(ctx, view, {
      overlay: this.overlay(this.step), truth, step: this.step, nodes: this.ctx.st.nodes,
      stale: this.stale.length > 0,
    });
  },

  /** The delay figure of the chosen link and the error chart, by the core's chart code. */
  drawCharts() {
    for (const id of ['chan-delays', 'chan-errors']) {
      const c = $(id);
      fitCanvas(c);
      if (!this.fig) c.getContext('2d').clearRect(0, 0, c.width, c.height);
    }
    this.delayBox = null;
    this.errorBox = null;
    this.segmentMarks = null;
    if (this.fig && this.active()) {
      try {
        const r = this.result;
        const link = this.s.link;
        this.delayBox = this.fig.draw_link_delays($('chan-delays'), link, 'Delays of one link', '');
        this.errorBox = this.fig.draw_error_time($('chan-errors'), 'Position error over time', '');
        // The segments over the core's chart (gaps shaded, each loss and its reason).
        this.segmentMarks = drawSegments($('chan-errors'), this.errorBox, r.track.segments || [], r.track.t_s);
      } catch (e) {
        showError(`Channel figures: ${errorText(e)}`);
        console.error(e);
      }
    }
    this.drawCursors();
  },

  /** The time cursor on both charts. */
  drawCursors() {
    const t = this.result ? this.result.track.t_s[this.step] : null;
    for (const [key, id, box] of [['delays', 'chan-delays', this.delayBox], ['errors', 'chan-errors', this.errorBox]]) {
      const c = $(id);
      this.cursorX[key] = drawCursor($(`${id}-cursor`), box, t, c.width, c.height);
    }
  },

  /** Saves `what` (the options of #chan-save-what) through export.js' download (so its hooks see it). */
  async save(what) {
    const figures = this.ctx.figures;
    const t0 = performance.now();
    try {
      if (!this.result) throw new Error('nothing to save yet: run the estimation first');
      const base = `${slug(this.ctx.app.scenario().name)}-channel`;
      const linkSlug = slug(this.result.names[this.s.link] || `link-${this.s.link}`);
      let blob;
      let name;
      if (what === 'delays-svg') {
        blob = new Blob([this.fig.delays_svg(0, 0, 'Delay estimates per link ([S] Fig. 4)', this.subtitle())], { type: 'image/svg+xml' });
        name = `${base}-delays.svg`;
      } else if (what === 'errors-svg') {
        blob = new Blob([this.fig.errors_svg(0, 0, `Track from channel recordings (${this.result.settings.filter.toUpperCase()})`, this.subtitle())], { type: 'image/svg+xml' });
        name = `${base}-track-figure.svg`;
      } else if (what === 'delays-png' || what === 'errors-png' || what === 'map-png') {
        const id = { 'delays-png': 'chan-delays', 'errors-png': 'chan-errors', 'map-png': 'plot' }[what];
        blob = await new Promise((resolve, reject) => {
          $(id).toBlob((b) => (b ? resolve(b) : reject(new Error('the canvas gave no image'))), 'image/png');
        });
        name = { 'delays-png': `${base}-delays-${linkSlug}.png`, 'errors-png': `${base}-errors.png`, 'map-png': `${base}-map.png` }[what];
      } else if (what === 'track-json') {
        // The file `cir track --out` writes (its text ends in a newline).
        blob = new Blob([`${this.result.texts.track}\n`], { type: 'application/json' });
        name = `${base}-track.json`;
      } else {
        throw new Error(`"${clip(what)}" is not something to save`);
      }
      figures.download(blob, name, { mode: 'channel', what, format: name.split('.').pop(), ms: performance.now() - t0 });
      const btn = $('chan-save');
      btn.dataset.saved = name;
      btn.dataset.count = String(Number(btn.dataset.count || 0) + 1);
    } catch (e) {
      showError(`Save: ${errorText(e)}`);
    }
  },

  /** The figures' subtitle: scenario, snapshots, filter. */
  subtitle() {
    const r = this.result;
    return `${this.ctx.app.scenario().name} · ${r.track.t_s.length} snapshots · ${r.settings.filter.toUpperCase()} · grey: static clusters (±3σ) · dashed: truth`;
  },
};
