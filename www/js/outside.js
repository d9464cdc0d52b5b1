// Nodes outside the scenario's area (an imported file or a shared link may place them there; the
// core accepts them: the area only bounds the map and the drags). Each is named in a warning,
// and the view's home extent is widened to the area plus those nodes (with a margin), so the view
// shows them, the area drawn as a dashed outline; a node too far away for that (it would shrink
// the area below a quarter of the view) is named with the reason and left out of the view.

/** Margin around the widened extent, a fraction of its larger side. */
const MARGIN = 0.05;
/** Largest widened side, a multiple of the area's side on that axis. */
export const MAX_WIDEN = 4;

/** A coordinate for a message: at most 6 significant digits, as the panel shows numbers. */
const num = (v) => String(Number(v.toPrecision(6)));

/**
 * The home extent of the scenario `area` [x0, x1, y0, y1] (m) with the nodes of `nodes`
 * (App.nodes(): {transmitters, receivers} of {x, y, name}): {home, outline (the area, or null
 * when the home is the area), warning (text, or '' when every node is inside)}.
 */
export function homeWithNodes(area, nodes) {
  const [x0, x1, y0, y1] = Array.from(area);
  const out = [];
  for (const [kind, list] of [['transmitter', nodes.transmitters], ['receiver', nodes.receivers]]) {
    for (const n of list) {
      if (!(n.x >= x0 && n.x <= x1 && n.y >= y0 && n.y <= y1)) out.push({ kind, ...n });
    }
  }
  if (!out.length) return { home: [x0, x1, y0, y1], outline: null, warning: '' };
  const areaText = `[${num(x0)}, ${num(x1)}] × [${num(y0)}, ${num(y1)}] m`;
  const where = (n) => `${n.kind} ${n.name} at (${num(n.x)}, ${num(n.y)}) m`;
  let [a, b, c, d] = [x0, x1, y0, y1];
  const shown = [];
  const far = [];
  for (const n of out) {
    const na = Math.min(a, n.x);
    const nb = Math.max(b, n.x);
    const nc = Math.min(c, n.y);
    const nd = Math.max(d, n.y);
    if ((nb - na) * (1 + 2 * MARGIN) > MAX_WIDEN * (x1 - x0) || (nd - nc) * (1 + 2 * MARGIN) > MAX_WIDEN * (y1 - y0)) {
      far.push(n);
    } else {
      [a, b, c, d] = [na, nb, nc, nd];
      shown.push(n);
    }
  }
  const parts = [];
  if (shown.length) {
    const list = shown.map(where).join(', ');
    parts.push(`${list} ${shown.length > 1 ? 'are' : 'is'} outside the area ${areaText}; the view is widened to show `
      + `${shown.length > 1 ? 'them' : 'it'} (the area is the dashed outline)`);
  }
  if (far.length) {
    const list = far.map(where).join(', ');
    parts.push(`${list} ${far.length > 1 ? 'are' : 'is'} outside the area ${areaText} and too far from it to show `
      + `(the view would be more than ${MAX_WIDEN} times the area's size); zoom out or edit the position in the panel`);
  }
  if (!shown.length) return { home: [x0, x1, y0, y1], outline: null, warning: parts.join(' · ') };
  const m = MARGIN * Math.max(b - a, d - c);
  return { home: [a - m, b + m, c - m, d + m], outline: [x0, x1, y0, y1], warning: parts.join(' · ') };
}
