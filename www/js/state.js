// The page state: one versioned plain-JSON object holding the whole state of every view, the one
// model behind "Save state" / "Open state" (a JSON file), "Copy link" (share.js) and undo/redo.
//
// The state is a registry of sections (registerSection): each gives `get()` (its part as plain
// JSON), `apply(value)` (puts it back) and optionally `check(value, pending)` (throws a named
// Error, `state.<section>.<field>: …`, on a bad value; `pending` carries what a later section's
// check needs from an earlier one, such as the new scenario's area). Restoring (restoreState)
// checks every section first and applies nothing unless all pass; should an apply still throw,
// the sections already applied are put back as they were. A section is applied only where it
// differs from what the page shows.
//
// Undo/redo is a bounded history of snapshots of the sections marked `history` (not the mode,
// the zoom window or the animation step): after every change of the page (ctx.changed, and any
// input event) the state is compared with the newest snapshot and, if it differs, pushed. A
// gesture is one step: nothing is recorded while a pointer is down, a key is held, a trajectory
// is drawn or a plan runs (its glides), so a drag, a held arrow key, a slider's slide or an
// Optimize each become one snapshot when they end. A section's `transient` fields (a time
// cursor, a playback speed) are saved and linked but are not edits: the history leaves them out,
// and an undo keeps them as they are.
//
// Each view registers its own section (its `register…State`, called by app.js in the order of
// restoring: channel, colours, scenario, grid, target, doppler, plan, tracking, mtl, view, mode); the
// checks read values with state-fields.js.

import { clip, errorText, showError, clearError, $ } from './dom.js';
import { MAX_BYTES } from './share.js';
import { isObject, shown } from './state-fields.js';

/** The `format` field of a state file. */
export const STATE_FORMAT = 'scatterloc-page-state';
/** The version of the state object; a state of another version is refused, naming both. */
export const STATE_VERSION = 1;
/** Largest state file (bytes) "Open state" reads: the link's cap. */
export const MAX_STATE_BYTES = MAX_BYTES;
/** Snapshots the undo history keeps (the oldest are dropped). */
export const HISTORY_MAX = 200;
/** While a gesture or a plan is going on, the history looks again this often, ms. */
const RETRY_MS = 60;

const sections = [];

/**
 * Registers a section of the state: `name` (its key in the state object) and {get, apply,
 * check?, history = true (undo covers it), optional = false (a state without it is accepted and
 * leaves it as it is), transient = [] (fields of its object value that are not edits, such as a
 * time cursor: saved and linked, left out of the undo history)}. Sections are applied in the
 * order registered.
 */
export function registerSection(name, {
  get, apply, check = null, history = true, optional = false, transient = [],
}) {
  if (sections.some((s) => s.name === name)) throw new Error(`state section ${name}: registered twice`);
  sections.push({ name, get, apply, check, history, optional, transient });
}

// ---------- the state object ----------

/** The whole state (every section), or only the sections `names`. */
export function captureState(names = null) {
  const out = { format: STATE_FORMAT, version: STATE_VERSION };
  for (const s of sections) if (!names || names.includes(s.name)) out[s.name] = s.get();
  return out;
}

/**
 * Checks a state object as restoreState would before applying anything (the envelope, the
 * sections present, every section's check) and returns the sections to apply, in order. Throws
 * a named Error (`state.<section>.<field>: …`) on the first bad field. `names`, `pending`: as
 * for restoreState.
 */
export function checkState(obj, { names = null, pending = {} } = {}) {
  if (!isObject(obj)) throw new Error(`state: ${shown(obj)} is not a JSON object`);
  if (obj.format !== STATE_FORMAT) throw new Error(`state.format: ${shown(obj.format)} is not "${STATE_FORMAT}"`);
  if (obj.version !== STATE_VERSION) {
    throw new Error(`state.version: ${shown(obj.version)} is not ${STATE_VERSION} (the version this page reads)`);
  }
  const known = ['format', 'version', ...sections.map((s) => s.name)];
  for (const k of Object.keys(obj)) {
    if (!known.includes(k)) throw new Error(`state.${clip(k)}: unknown section (known: ${known.join(', ')})`);
  }
  const list = [];
  for (const s of sections) {
    if (names && !names.includes(s.name)) continue;
    if (!(s.name in obj)) {
      if (s.optional || names) continue;
      throw new Error(`state.${s.name}: missing`);
    }
    list.push(s);
  }
  for (const s of list) if (s.check) s.check(obj[s.name], pending);
  return list;
}

/**
 * Restores a state object (a file's, a link's or a snapshot of the history): checks everything
 * (checkState), then applies the sections that differ. `names`: only these sections (the rest
 * may be absent); `pending`: facts known beforehand (a link's scenario). Throws a named Error
 * and changes nothing on a bad field.
 */
export function restoreState(obj, { names = null, pending = {} } = {}) {
  const list = checkState(obj, { names, pending });
  const done = [];
  try {
    for (const s of list) {
      const before = s.get();
      if (JSON.stringify(before) === JSON.stringify(obj[s.name])) continue;
      done.push([s, before]);
      s.apply(obj[s.name], pending);
    }
  } catch (e) {
    for (const [s, before] of done.reverse()) {
      try { s.apply(before, {}); } catch (_) { /* best effort */ }
    }
    throw e;
  }
}

// ---------- the model ----------

/**
 * Starts the history, the buttons (Undo, Redo, Save state, Open state), the keyboard shortcuts
 * and the confirmation before a scenario switch, over the sections registered so far.
 * @param {object} p - {app, panel, tracking, plan, ctx (app.js ctx: its `changed` is wrapped so
 *   that every change is looked at)}
 * @returns the state model: {openLink, checkLink, linkState, save, undo, redo, dirty, hooks()}
 */
export function attachState(p) {
  return new StateModel(p);
}

// ---------- history, files, links, the confirm dialog ----------

class StateModel {
  constructor(p) {
    this.p = p;
    this.entries = []; // JSON text of the history sections' snapshots
    this.index = -1;
    this.clean = null; // what a scenario switch would lose, as of the last load or save (JSON text)
    this.cleanPending = true;
    this.replaceNext = false; // the next snapshot replaces the current (after an undo's refresh)
    this.restoring = false;
    this.scheduled = false;
    this.pointers = 0;
    this.keys = new Set();
    this.lastSaved = null; // {name, text} of the last "Save state"
    this.dryRun = false; // tests: build the file without clicking its link
    this.planMark = null; // the history index before the running or last Optimize
    this.bindEvents();
    this.bindPlan();
    this.bindSwitch();
    // Every change of the page passes ctx.changed: look at the state after the refresh it asks for.
    const inner = p.ctx.changed;
    p.ctx.changed = (flags) => {
      inner(flags);
      this.note();
    };
    this.note();
  }

  historyNames() { return sections.filter((s) => s.history).map((s) => s.name); }

  /** The history's snapshot of the page now: the history sections, without their transient fields. */
  docText() {
    const o = {};
    for (const s of sections) {
      if (!s.history) continue;
      const v = s.get();
      if (s.transient.length && isObject(v)) {
        o[s.name] = Object.fromEntries(Object.entries(v).filter(([k]) => !s.transient.includes(k)));
      } else {
        o[s.name] = v;
      }
    }
    return JSON.stringify(o);
  }

  /** What a scenario switch (preset, import, Open state) would discard: the scenario, the target, the ROI. */
  switchText(doc) {
    const d = JSON.parse(doc);
    return JSON.stringify([d.scenario.json, d.target.point, d.plan.roi]);
  }

  /** True when the scenario, the target or the ROI differ from the last one loaded or saved. */
  dirty() {
    this.check(true);
    if (this.index < 0) return false;
    return this.clean !== null && this.switchText(this.entries[this.index]) !== this.clean;
  }

  /** A change happened: look at the state once the frame's refresh has run. */
  note() {
    if (this.scheduled || this.restoring) return;
    this.scheduled = true;
    requestAnimationFrame(() => setTimeout(() => {
      this.scheduled = false;
      this.check(false);
    }, 0));
  }

  busy() {
    const { plan, tracking } = this.p;
    return this.pointers > 0 || this.keys.size > 0 || plan.status === 'running' || !!plan.glide || tracking.dragging;
  }

  /**
   * Records the state if it differs from the current snapshot (`force`: even while a key is
   * held, as for Ctrl+Z itself; never in the middle of a pointer gesture or a plan).
   */
  check(force) {
    if (this.restoring) return;
    const { plan, tracking } = this.p;
    const gesture = this.pointers > 0 || plan.status === 'running' || !!plan.glide || tracking.dragging;
    if (gesture || (!force && this.busy())) {
      if (!force) setTimeout(() => this.note(), RETRY_MS);
      return;
    }
    let t;
    try {
      t = this.docText();
    } catch (e) {
      console.error(e);
      return;
    }
    if (this.entries.length === 0) {
      this.entries = [t];
      this.index = 0;
    } else if (t !== this.entries[this.index]) {
      if (this.replaceNext) {
        this.entries[this.index] = t;
      } else {
        // A new edit over undone steps drops them, and with them the Optimize the Plan panel would undo.
        const truncates = this.index < this.entries.length - 1;
        if (this.planMark !== null && truncates && this.index <= this.planMark) this.planMark = null;
        this.entries.splice(this.index + 1);
        this.entries.push(t);
        if (this.entries.length > HISTORY_MAX) {
          this.entries.shift();
          if (this.planMark !== null) this.planMark = this.planMark > 0 ? this.planMark - 1 : null;
        }
        this.index = this.entries.length - 1;
      }
    }
    this.replaceNext = false;
    if (this.cleanPending) {
      this.clean = this.switchText(t);
      this.cleanPending = false;
    }
    this.syncButtons();
  }

  syncButtons() {
    $('undo').disabled = this.index <= 0;
    $('redo').disabled = this.index >= this.entries.length - 1;
  }

  /** Goes to snapshot `i` of the history. */
  go(i) {
    const { plan } = this.p;
    if (this.pointers > 0) return false;
    plan.cancel('undo');
    this.check(true);
    if (i < 0 || i >= this.entries.length || i === this.index) return false;
    const obj = { format: STATE_FORMAT, version: STATE_VERSION, ...JSON.parse(this.entries[i]) };
    // The transient fields (a cursor, a speed) stay as they are now (in get()'s order of fields).
    for (const s of sections) {
      if (s.history && s.transient.length && isObject(obj[s.name])) obj[s.name] = { ...s.get(), ...obj[s.name] };
    }
    this.restoring = true;
    try {
      restoreState(obj, { names: this.historyNames() });
      this.index = i;
      clearError();
    } catch (e) {
      showError(`Undo: ${errorText(e)}`);
      return false;
    } finally {
      this.restoring = false;
    }
    if (this.planMark !== null) {
      // The Plan panel's Undo is available while the history is past the snapshot before Optimize.
      const before = JSON.parse(this.entries[this.planMark]).scenario;
      plan.undoJson = this.index > this.planMark ? JSON.stringify(before.json) : null;
      plan.undoPreset = before.preset;
      if (plan.undoJson === null) plan.applied = null;
      plan.sync();
    }
    this.replaceNext = true;
    this.note();
    this.syncButtons();
    return true;
  }

  undo() { return this.go(this.index - 1); }

  redo() { return this.go(this.index + 1); }

  bindEvents() {
    const { panel } = this.p;
    // The gestures that edit continuously: a press on the plot (a drag) or on a slider.
    addEventListener('pointerdown', (ev) => {
      const t = ev.target;
      if (t && (t.id === 'plot' || (t.tagName === 'INPUT' && t.type === 'range'))) this.pointers = 1;
    }, true);
    const up = () => {
      this.pointers = 0;
      this.note();
    };
    addEventListener('pointerup', up, true);
    addEventListener('pointercancel', up, true);
    addEventListener('keydown', (ev) => {
      if (!['Control', 'Meta', 'Shift', 'Alt'].includes(ev.key) && !ev.ctrlKey && !ev.metaKey) this.keys.add(ev.key);
    }, true);
    addEventListener('keyup', (ev) => {
      this.keys.delete(ev.key);
      if (ev.key.length === 1) { this.keys.delete(ev.key.toLowerCase()); this.keys.delete(ev.key.toUpperCase()); }
      this.note();
    }, true);
    addEventListener('blur', () => {
      this.keys.clear();
      this.pointers = 0;
      this.note();
    });
    for (const type of ['change', 'input', 'click']) document.addEventListener(type, () => this.note());
    // Ctrl/Cmd+Z undoes, Shift+Ctrl/Cmd+Z and Ctrl/Cmd+Y redo; in a text field the browser's own undo.
    addEventListener('keydown', (ev) => {
      if (!(ev.ctrlKey || ev.metaKey) || ev.altKey) return;
      const key = ev.key.toLowerCase();
      if (key !== 'z' && key !== 'y') return;
      const el = document.activeElement;
      const text = el && (el.tagName === 'TEXTAREA' || el.isContentEditable || (el.tagName === 'INPUT'
        && !['checkbox', 'radio', 'range', 'button', 'submit', 'file', 'color'].includes(el.type)));
      if (text) return;
      ev.preventDefault();
      if (key === 'y' || ev.shiftKey) this.redo(); else this.undo();
    });
    $('undo').addEventListener('click', () => this.undo());
    $('redo').addEventListener('click', () => this.redo());
    $('state-save').addEventListener('click', () => this.save());
    $('state-file').addEventListener('change', async (e) => {
      const file = e.target.files && e.target.files[0];
      e.target.value = '';
      if (!file) return;
      await this.openFile(file);
    });
    // Loading a scenario is a new baseline of "unsaved edits".
    const importText = panel.importText.bind(panel);
    panel.importText = (text, name) => {
      const ok = importText(text, name);
      if (ok) this.cleanPending = true;
      return ok;
    };
    const exportJson = panel.exportJson.bind(panel);
    panel.exportJson = () => {
      exportJson();
      this.check(true);
      this.clean = this.switchText(this.entries[this.index]);
    };
  }

  /** The Plan panel's Undo is the history's: back to the snapshot from before Optimize. */
  bindPlan() {
    const { plan } = this.p;
    const start = plan.start.bind(plan);
    plan.start = (overrides) => {
      this.check(true);
      const mark = this.index;
      const r = start(overrides);
      if (r === null) this.planMark = mark;
      return r;
    };
    plan.undo = () => {
      if (plan.undoJson === null || this.planMark === null) return false;
      plan.cancel('undo');
      this.check(true);
      if (this.index <= this.planMark) return false;
      return this.go(this.planMark);
    };
  }

  // ---------- the confirm before a scenario switch ----------

  /** Asks (the page's dialog) whether to discard the unsaved edits; resolves true or false. */
  confirm(what) {
    const d = $('confirm-dialog');
    $('confirm-text').textContent = `${what} replaces the current scenario, and its edits have not been saved. `
      + 'Undo can bring them back.';
    return new Promise((resolve) => {
      const close = (ok) => {
        $('confirm-ok').onclick = null;
        $('confirm-cancel').onclick = null;
        d.oncancel = null;
        if (d.open) d.close();
        resolve(ok);
      };
      $('confirm-ok').onclick = () => close(true);
      $('confirm-cancel').onclick = () => close(false);
      d.oncancel = (ev) => {
        ev.preventDefault();
        close(false);
      };
      d.showModal();
      $('confirm-cancel').focus();
    });
  }

  bindSwitch() {
    const { panel } = this.p;
    let pass = false;
    // Capture on the document: before the panel's own listeners.
    document.addEventListener('change', async (ev) => {
      const el = ev.target;
      if (el.id === 'preset') {
        if (pass) {
          pass = false;
          this.cleanPending = true;
          return;
        }
        const name = el.value;
        if (!name) return;
        // The select shows the new name already: judge the state with the one loaded.
        const loaded = this.index >= 0 ? JSON.parse(this.entries[this.index]).scenario.preset : name;
        el.value = loaded;
        const dirty = this.dirty();
        el.value = name;
        if (!dirty) {
          this.cleanPending = true;
          return;
        }
        ev.stopImmediatePropagation();
        // Back to what is loaded; the option chosen is replaced by its copy, so that choosing it
        // again is a change the browser reports.
        const chosen = [...el.options].find((o) => o.value === name);
        chosen.replaceWith(chosen.cloneNode(true));
        el.value = loaded;
        const asking = this.confirm(`Loading the scenario ${name}`);
        // (Some automation selects the option again after its change event: show what is loaded.)
        setTimeout(() => { if (!pass) el.value = loaded; }, 0);
        if (await asking) {
          el.value = name;
          pass = true;
          el.dispatchEvent(new Event('change', { bubbles: true }));
        }
      } else if (el.id === 'import-file') {
        const file = el.files && el.files[0];
        if (!file || !this.dirty()) return;
        ev.stopImmediatePropagation();
        el.value = '';
        if (await this.confirm(`Importing ${file.name}`)) panel.importText(await file.text(), file.name);
      }
    }, true);
  }

  // ---------- files and links ----------

  /** "Save state": downloads the whole state as JSON; the scenario counts as saved. */
  save() {
    const text = `${JSON.stringify(captureState(), null, 1)}\n`;
    const name = `${(JSON.parse(this.p.app.scenario_json()).name || 'scenario').replace(/[^\w.-]+/g, '_')}-state.json`;
    this.lastSaved = { name, text };
    this.check(true);
    this.clean = this.switchText(this.entries[this.index]);
    if (this.dryRun) return;
    const url = URL.createObjectURL(new Blob([text], { type: 'application/json' }));
    const a = document.createElement('a');
    a.href = url;
    a.download = name;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  }

  /** "Open state": a state file, read strictly (size cap, JSON, every field); asks first over unsaved edits. */
  async openFile(file) {
    if (file.size > MAX_STATE_BYTES) {
      showError(`Open state (${clip(file.name)}): ${file.size} bytes, more than the ${MAX_STATE_BYTES} bytes a state file may have`);
      return false;
    }
    let obj;
    try {
      obj = JSON.parse(await file.text());
    } catch (e) {
      showError(`Open state (${clip(file.name)}): not JSON (${errorText(e)})`);
      return false;
    }
    if (this.dirty() && !(await this.confirm(`Opening ${file.name}`))) return false;
    return this.openObject(obj, `Open state (${clip(file.name)})`);
  }

  /** Restores a state object; a bad one is named in the banner (`what: …`) and nothing changes. */
  openObject(obj, what) {
    this.check(true);
    try {
      restoreState(obj);
    } catch (e) {
      showError(`${what}: ${errorText(e)}`);
      return false;
    }
    clearError();
    this.cleanPending = true;
    this.note();
    return true;
  }

  /** The state for a link: the scenario travels as the link's own scenario option. */
  linkState() {
    const s = captureState();
    s.scenario = { ...s.scenario, json: null };
    return JSON.stringify(s);
  }

  /**
   * Copy link's read-back of its own state part (`text`, decoded from the link as the opened page
   * will decode it): throws the named Error the opened page would give unless every section
   * passes the checks a restore makes first (checkState, with the link's own scenario option).
   */
  checkLink(text) {
    checkState(JSON.parse(text), { pending: { linkScenario: true } });
  }

  /** A link's state (its JSON text, the scenario given by the link's scenario option): null or the message. */
  openLink(text) {
    let obj;
    try {
      obj = JSON.parse(text);
    } catch (e) {
      return `not JSON (${errorText(e)})`;
    }
    try {
      restoreState(obj, { pending: { linkScenario: true } });
    } catch (e) {
      return errorText(e);
    } finally {
      this.entries = [];
      this.index = -1;
      this.cleanPending = true;
      this.note();
    }
    return null;
  }

  /** Test and console hook (window.pageStateModel). */
  hooks() {
    return {
      capture: () => captureState(),
      restore: (obj) => this.openObject(obj, 'state') ? null : document.getElementById('error-text').textContent,
      history: () => ({
        index: this.index, length: this.entries.length, pending: this.scheduled, busy: this.busy(), planMark: this.planMark,
      }),
      undo: () => this.undo(),
      redo: () => this.redo(),
      dirty: () => this.dirty(),
      lastSaved: () => this.lastSaved,
      setDryRun: (on) => { this.dryRun = !!on; },
    };
  }
}
