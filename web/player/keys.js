// The player's key table as data: api/keys.json, generated from the C++ table (src/player/keys.cpp)
// by `panoptes serve` and `panoptes export-web` (format: the top of docs/web.md), so the browser keeps
// no second copy of it. A key press matches a binding, the binding names an action, the table's
// `actions` says what the action does in the database's mode (sphere, panorama, lattice) — an
// operation the player executes.

export const MODES = ["sphere", "panorama", "lattice"];

/// Checks and indexes keys.json. Throws Error naming the source and what is wrong.
export function parseKeyTable(json, source = "keys.json") {
  const rows = json && json.bindings;
  if (!Array.isArray(rows) || rows.length === 0) throw new Error(`${source}: no "bindings" (expected the format of docs/web.md)`);
  for (const [i, r] of rows.entries())
    if (!r || typeof r.desktop !== "string" || typeof r.action !== "string" || !Array.isArray(r.keys))
      throw new Error(`${source}: binding ${i} lacks "desktop", "action" or "keys"`);
  if (json.mode !== undefined && !MODES.includes(json.mode)) throw new Error(`${source}: unknown mode "${json.mode}"`);
  // event.key → bindings, in the table's order.
  const byKey = new Map();
  for (const r of rows)
    for (const k of r.keys) {
      if (!byKey.has(k)) byKey.set(k, []);
      byKey.get(k).push(r);
    }
  return { rows, byKey, mode: json.mode ?? null, actions: json.actions ?? {}, walk: json.walk ?? null, look: json.look ?? null,
           playback: json.playback ?? null, numbering: json.numbering ?? null,
           // Actions that can change nothing in this database (C++ player::usable: no parameter axes, one
           // camera shell, C on perspective frames): the help leaves them out, as the window's does.
           unusable: new Set(Array.isArray(json.unusable) ? json.unusable : []) };
}

/// The binding of a keydown event, by keys.json's match_rule (player::binding_for_chord): event.key
/// among its keys, its `shift` (when it names one) equal to event.shiftKey, its `ctrl` and `alt` equal
/// to event.ctrlKey and event.altKey; failing that, with Shift alone held, the binding that names
/// shift false (Shift+L acts as L, as on the desktop). Meta matches nothing. Undefined if none.
export function bindingOf(e, table) {
  if (!table || e.metaKey) return undefined;
  const rows = table.byKey.get(e.key) ?? [];
  const mods = (r) => !!r.ctrl === e.ctrlKey && !!r.alt === e.altKey;
  return rows.find((r) => mods(r) && (r.shift === undefined || r.shift === e.shiftKey)) ??
    (e.shiftKey && !e.ctrlKey && !e.altKey ? rows.find((r) => mods(r) && r.shift === false) : undefined);
}

/// What a refused press of the binding says in the mode (keys.json's `refusal`, player::refusal: the
/// window shows the same words); "" when a refusal needs none.
export function refusalOf(table, binding, mode) {
  const r = binding && binding.refusal;
  return (r && typeof r === "object" && r[mode]) || "";
}

/// What an action does in a mode: the table's operation, null for nothing, the action's own name
/// when the table has no `actions` entry for it.
export function operationOf(table, action, mode) {
  const a = table.actions[action];
  if (!a || !(mode in a)) return action;
  return a[mode];
}

/// Key names as a person reads them.
const SHOWN = { Left: "←", Right: "→", Up: "↑", Down: "↓", Period: ".", Comma: ",", "Shift+Period": ">", "Shift+Comma": "<",
                PageUp: "PgUp", PageDown: "PgDn" };
const shown = (k) => SHOWN[k] ?? k;

/// The help rows for the mode: [{keys, text, action}], the table's order, keys of one action with the
/// same text on one line, digit keys folded into the first. Bindings not active in the mode, whose
/// action this player cannot do (`unsupported`: a Set of action names) or that can change nothing in
/// the database (the table's `unusable`), are left out.
export function helpRows(table, mode, unsupported = new Set()) {
  const out = [], byAction = new Map();
  for (const r of table.rows) {
    if (unsupported.has(r.action) || table.unusable?.has(r.action) || (Array.isArray(r.modes) && !r.modes.includes(mode))) continue;
    if (operationOf(table, r.action, mode) === null) continue;
    const d = r.description;
    const text = (d && typeof d === "object" ? d[mode] : d) ?? r.action;
    const prev = byAction.get(r.action);
    if (prev && prev.text === text) { prev.keys.push(shown(r.desktop)); continue; }
    if (/^task_[2-9]$/.test(r.action) && byAction.has("task_1")) continue;
    const row = { keys: [shown(r.desktop)], text, action: r.action };
    byAction.set(r.action, row);
    out.push(row);
  }
  return out.map((r) => ({ keys: r.keys.join(", "), text: r.text, action: r.action }));
}
