// The side panel: scenario inputs, node lists, import/export and the target read-out. Every edit
// goes to a validating wasm setter; a rejected value shows its message in the error banner and
// leaves the scenario unchanged.

import { $, errorText, fillKeyValues, fixed, showError, clearError } from './dom.js';
import { linkColor } from './draw.js';
import { readNumber, showNumber } from './numfield.js';
import { homeWithNodes } from './outside.js';
import { registerSection } from './state.js';
import { choice, fields, isObject, shown } from './state-fields.js';

export class Panel {
  /**
   * @param {object} ctx - { app, wasm, st, changed(flags), view }
   */
  constructor(ctx) {
    this.ctx = ctx;
    const { wasm } = ctx;
    const preset = $('preset');
    for (const name of wasm.preset_names()) preset.add(new Option(name, name));
    preset.add(new Option('(imported / edited)', ''));
    preset.addEventListener('change', () => {
      // Read first: run() cancels a running plan, whose last layout marks the select "edited".
      const name = preset.value;
      if (name && this.run(null, () => this.ctx.app.load_preset(name), { all: true, reset: true })) preset.value = name;
    });
    $('error-close').addEventListener('click', clearError);

    // Radio (SI in the core; GHz/MHz on screen).
    this.bind('carrier', (v) => ctx.app.set_carrier_hz(v * 1e9));
    this.bind('bandwidth', (v) => ctx.app.set_bandwidth_hz(v * 1e6));
    this.bind('nf', (v) => ctx.app.set_noise_figure_db(v));
    this.bind('rcs', (v) => ctx.app.set_rcs_m2(v));
    // Heights (issue 40, docs/rooms-3d.md): the target's plane here, each node's below.
    this.bind('target-h', (v) => ctx.app.set_target_height_m(v));

    // Selected transmitter.
    const tx = () => ctx.st.selTx;
    this.bind('tx-x', (v) => ctx.app.move_transmitter(tx(), v, this.field('tx-y')));
    this.bind('tx-y', (v) => ctx.app.move_transmitter(tx(), this.field('tx-x'), v));
    this.bind('tx-h', (v) => ctx.app.set_tx_height_m(tx(), v));
    this.bind('tx-power', (v) => ctx.app.set_tx_power_dbm(tx(), v));
    this.bind('tx-gain', (v) => ctx.app.set_tx_gain_dbi(tx(), v));
    const pattern = () => ctx.app.set_tx_pattern(tx(), $('tx-pattern').value,
      this.field('tx-boresight'), this.field('tx-beamwidth'), this.field('tx-floor'));
    for (const id of ['tx-boresight', 'tx-beamwidth', 'tx-floor']) this.bind(id, pattern);
    $('tx-pattern').addEventListener('change', () => {
      // Switching to a beam: start from the spec's §9.3 defaults for empty fields.
      for (const [id, d] of [['tx-boresight', '0'], ['tx-beamwidth', '70'], ['tx-floor', '20']]) {
        if ($(id).value.trim() === '') $(id).value = d;
      }
      this.run($('tx-pattern'), pattern);
    });

    // Selected receiver.
    const rx = () => ctx.st.selRx;
    this.bind('rx-x', (v) => ctx.app.move_receiver(rx(), v, this.field('rx-y')));
    this.bind('rx-y', (v) => ctx.app.move_receiver(rx(), this.field('rx-x'), v));
    this.bind('rx-h', (v) => ctx.app.set_rx_height_m(rx(), v));
    this.bind('rx-gain', (v) => ctx.app.set_rx_gain_dbi(rx(), v));

    $('tx-select').addEventListener('change', (e) => this.select('tx', Number(e.target.value)));
    $('rx-select').addEventListener('change', (e) => this.select('rx', Number(e.target.value)));
    $('tx-add').addEventListener('click', () => this.addNode('tx'));
    $('rx-add').addEventListener('click', () => this.addNode('rx'));
    $('tx-remove').addEventListener('click', () => this.removeNode('tx'));
    $('rx-remove').addEventListener('click', () => this.removeNode('rx'));
    $('resolution').addEventListener('change', () => ctx.changed({ map: true }));

    // Import / export (same JSON schema as the CLI).
    $('export').addEventListener('click', () => this.exportJson());
    $('import-file').addEventListener('change', async (e) => {
      const file = e.target.files && e.target.files[0];
      if (!file) return;
      try {
        this.importText(await file.text(), file.name);
      } finally {
        e.target.value = '';
      }
    });
    $('target-clear').addEventListener('click', () => ctx.clearTarget());
    $('target-resample').addEventListener('click', () => ctx.resample());
  }

  /**
   * The number in input `id`: the exact value behind its rounded display while untouched
   * (numfield.js), else strictly parsed; a bad one throws naming the scenario field.
   */
  field(id) {
    return readNumber($(id), this.fieldName(id));
  }

  /** The scenario field input `id` edits (the path the core's messages use). */
  fieldName(id) {
    const { selTx, selRx } = this.ctx.st;
    return {
      carrier: 'radio.carrier_hz (GHz)',
      bandwidth: 'radio.bandwidth_hz (MHz)',
      nf: 'radio.noise_figure_db',
      rcs: 'target.rcs_m2',
      'target-h': 'target.height_m',
      'tx-x': `transmitters[${selTx}].position_m[0]`,
      'tx-y': `transmitters[${selTx}].position_m[1]`,
      'tx-h': `transmitters[${selTx}].height_m`,
      'tx-power': `transmitters[${selTx}].power_dbm`,
      'tx-gain': `transmitters[${selTx}].gain_dbi`,
      'tx-boresight': `transmitters[${selTx}].pattern.boresight_deg`,
      'tx-beamwidth': `transmitters[${selTx}].pattern.beamwidth_deg`,
      'tx-floor': `transmitters[${selTx}].pattern.floor_db`,
      'rx-x': `receivers[${selRx}].position_m[0]`,
      'rx-y': `receivers[${selRx}].position_m[1]`,
      'rx-h': `receivers[${selRx}].height_m`,
      'rx-gain': `receivers[${selRx}].gain_dbi`,
    }[id] ?? id;
  }

  /** Commits an input on change (Enter or blur). */
  bind(id, setter) {
    $(id).addEventListener('change', () => this.run($(id), () => setter(this.field(id))));
    $(id).setAttribute('inputmode', 'decimal');
    $(id).setAttribute('autocomplete', 'off');
    $(id).setAttribute('spellcheck', 'false');
  }

  /**
   * Runs a wasm edit; on success refreshes, on failure shows the core's message. Any edit cancels
   * a running plan first (plan.js), which would otherwise overwrite it with its next layout.
   */
  run(input, edit, flags = { all: true }) {
    if (this.ctx.plan) this.ctx.plan.cancel('scenario edited');
    try {
      edit();
      if (input) input.classList.remove('invalid');
      document.querySelectorAll('input.invalid').forEach((el) => el.classList.remove('invalid'));
      clearError();
      if (!flags.reset) $('preset').value = '';
      this.ctx.changed(flags);
      return true;
    } catch (e) {
      if (input) input.classList.add('invalid');
      showError(errorText(e));
      return false;
    }
  }

  /** Loads scenario JSON text (an imported file); errors name the file and the field. */
  importText(text, name = 'scenario.json') {
    const ok = this.run(null, () => this.ctx.app.set_scenario_json(text), { all: true, reset: true });
    if (ok) {
      $('preset').value = '';
    } else {
      showError(`Import of ${name} failed: ${$('error-text').textContent}`);
    }
    return ok;
  }

  exportJson() {
    const text = this.ctx.app.scenario_json();
    const name = (JSON.parse(text).name || 'scenario').replace(/[^\w.-]+/g, '_');
    const url = URL.createObjectURL(new Blob([text + '\n'], { type: 'application/json' }));
    const a = document.createElement('a');
    a.href = url;
    a.download = `${name}.json`;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  }

  addNode(kind) {
    const [x0, x1, y0, y1] = this.ctx.app.area();
    const c = this.ctx.view.toMetre(this.ctx.view.rect.x + this.ctx.view.rect.w / 2, this.ctx.view.rect.y + this.ctx.view.rect.h / 3);
    // In the window shown (zoom.js) and in the area.
    const x = Number.isFinite(c.x) ? Math.min(Math.max(c.x, x0), x1) : (x0 + x1) / 2;
    const y = Number.isFinite(c.y) ? Math.min(Math.max(c.y, y0), y1) : (y0 + y1) / 2;
    this.run(null, () => {
      const i = kind === 'tx' ? this.ctx.app.add_transmitter(x, y) : this.ctx.app.add_receiver(x, y);
      this.select(kind, i, false);
    });
  }

  /**
   * Removes the selected transmitter or receiver (the Remove buttons and Delete on the plot);
   * the core refuses the last one (its message in the banner). Returns whether it was removed.
   */
  removeNode(kind) {
    const { app, st } = this.ctx;
    const i = kind === 'tx' ? st.selTx : st.selRx;
    return this.run(null, () => {
      if (kind === 'tx') app.remove_transmitter(i); else app.remove_receiver(i);
      this.select(kind, Math.max(0, i - 1), false);
    });
  }

  select(kind, index, redraw = true) {
    const st = this.ctx.st;
    if (kind === 'tx') st.selTx = index; else st.selRx = index;
    st.selected = { kind, index };
    if (redraw) this.ctx.changed({ draw: true });
  }

  /** Fills the inputs from the scenario (skipping the one being typed in). */
  sync() {
    const { app, st } = this.ctx;
    const s = app.scenario();
    st.selTx = Math.min(st.selTx, s.transmitters.length - 1);
    st.selRx = Math.min(st.selRx, s.receivers.length - 1);
    const set = (id, v) => {
      const el = $(id);
      if (document.activeElement === el && el.classList.contains('invalid')) return;
      if (document.activeElement !== el) showNumber(el, v);
      el.classList.remove('invalid');
    };
    set('carrier', s.radio.carrier_hz / 1e9);
    set('bandwidth', s.radio.bandwidth_hz / 1e6);
    set('nf', s.radio.noise_figure_db ?? (s.radio.noise_power_dbm === undefined ? 10 : ''));
    $('nf').placeholder = s.radio.noise_power_dbm === undefined ? '' : `P_n ${s.radio.noise_power_dbm} dBm`;
    set('rcs', s.target.rcs_m2);
    set('target-h', s.target.height_m ?? 0); // omitted from the JSON when 0
    fillSelect($('tx-select'), s.transmitters, st.selTx);
    fillSelect($('rx-select'), s.receivers, st.selRx);
    const t = s.transmitters[st.selTx];
    set('tx-x', t.position_m[0]);
    set('tx-y', t.position_m[1]);
    set('tx-h', t.height_m ?? 0);
    set('tx-power', t.power_dbm);
    set('tx-gain', t.gain_dbi);
    const p = t.pattern || { kind: 'omni' };
    $('tx-pattern').value = p.kind;
    const beam = p.kind === 'parabolic';
    for (const [id, v] of [['tx-boresight', p.boresight_deg], ['tx-beamwidth', p.beamwidth_deg], ['tx-floor', p.floor_db]]) {
      set(id, beam ? v : '');
      $(id).disabled = !beam;
    }
    const r = s.receivers[st.selRx];
    set('rx-x', r.position_m[0]);
    set('rx-y', r.position_m[1]);
    set('rx-h', r.height_m ?? 0);
    set('rx-gain', r.gain_dbi);
    $('tx-remove').disabled = s.transmitters.length < 2;
    $('rx-remove').disabled = s.receivers.length < 2;
    $('status-scenario').textContent =
      `${s.name} · ${s.transmitters.length} Tx · ${s.receivers.length} Rx · ${app.link_count()} links`;
  }

  /** The target read-out (all values and labels come from the core). */
  showTarget(fix) {
    const box = $('target-info');
    $('target-clear').disabled = !fix;
    $('target-resample').disabled = !fix;
    if (!fix) return;
    const m = (v) => `${fixed(v, 3)} m`;
    // The target's plane (issue 40): shown only off the floor, so a planar page reads as before.
    const h = this.ctx.app.target_height_m();
    const rows = [
      ['Target', `${m(fix.truth.x)}, ${m(fix.truth.y)}${h ? ` · h ${m(h)}` : ''}`, ''],
      ['CRLB RMSE', fix.crlb.rmse_label, 'crlb'],
      ['CRLB σx / σy', `${fix.crlb.sigma_x_label} / ${fix.crlb.sigma_y_label}`, 'crlb'],
    ];
    if (fix.fix) {
      rows.push(['LM fix', `${m(fix.fix.x)}, ${m(fix.fix.y)}`, 'fix']);
      rows.push(['Fix error', fix.fix.error_label, 'fix']);
      rows.push(['LM', `${fix.fix.iterations} it. · ${fix.fix.termination.replace('_', ' ')}`, '']);
    }
    rows.push(['Noise seed', String(fix.seed), '']);
    box.replaceChildren();
    const dl = document.createElement('dl');
    dl.className = 'kv';
    fillKeyValues(dl, rows);
    box.append(dl);
    // One line per link: its colour in the plot, name and range noise cσ_τ at the target.
    const links = document.createElement('div');
    links.className = 'links';
    const head = document.createElement('div');
    head.className = 'links-head';
    head.textContent = 'Links (plot colour) · range noise c·σ_τ at the target';
    links.append(head);
    fix.links.forEach((l, i) => {
      const row = document.createElement('div');
      const sw = document.createElement('i');
      sw.style.background = linkColor(i);
      const name = document.createElement('span');
      name.textContent = l.name;
      const note = document.createElement('span');
      note.className = 'muted';
      note.textContent = l.ellipse ? '' : 'no ellipse (below LoS delay)';
      const v = document.createElement('b');
      v.textContent = l.range_sigma_label;
      row.append(sw, name, note, v);
      links.append(row);
    });
    box.append(links);
    if (fix.fix_error) {
      const p = document.createElement('p');
      p.className = 'note warn';
      p.textContent = `No LM fix: ${fix.fix_error}`;
      box.append(p);
    } else if (fix.fix && !fix.fix.converged) {
      const p = document.createElement('p');
      p.className = 'note warn';
      p.textContent = 'LM stopped without converging.';
      box.append(p);
    }
  }
}

function fillSelect(sel, nodes, index) {
  const names = nodes.map((n) => n.name);
  if ([...sel.options].map((o) => o.text).join('\n') !== names.join('\n')) {
    sel.replaceChildren(...names.map((n, i) => new Option(n, String(i))));
  }
  sel.value = String(index);
}

/**
 * Registers the page state's `scenario` section: the preset's name and the scenario JSON (a
 * link's state carries `json: null`, the link giving the scenario itself). Its check loads the
 * scenario into a scratch App and hands its area and home to the later sections (`pending`).
 * @param {object} p - {app, wasm, st, plan, ctx (ctx.changed), homeFor (app.js setHomeFor)}
 */
export function registerScenarioState({ app, wasm, st, plan, ctx, homeFor }) {
  registerSection('scenario', {
    get: () => ({ preset: $('preset').value, json: JSON.parse(app.scenario_json()) }),
    check: (v, pending) => {
      fields(v, 'state.scenario', ['preset', 'json']);
      choice(v.preset, 'state.scenario.preset', 'preset');
      if (v.json === null && pending.linkScenario) return; // the link's own scenario option
      if (!isObject(v.json)) throw new Error(`state.scenario.json: ${shown(v.json)} is not a scenario object`);
      const scratch = wasm.App.from_preset(wasm.preset_names()[0]);
      try {
        scratch.set_scenario_json(JSON.stringify(v.json));
        pending.area = Array.from(scratch.area());
        pending.home = homeWithNodes(pending.area, scratch.nodes()).home;
      } catch (e) {
        throw new Error(`state.scenario.json: ${errorText(e)}`);
      } finally {
        scratch.free();
      }
    },
    apply: (v) => {
      if (v.json !== null) {
        plan.cancel('state restored');
        const text = JSON.stringify(v.json);
        if (app.scenario_json() !== text) app.set_scenario_json(text);
        homeFor();
        st.nodes = app.nodes();
        ctx.changed({ all: true });
      }
      $('preset').value = v.preset;
    },
  });
}
