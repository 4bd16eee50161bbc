// The player's key table as data: keys.json, generated from the C++ table (src/player/keys.cpp) by
// `panoptes serve` and `panoptes export-web` (docs/web.md), so the browser has no second copy of it.
// A key press becomes the table's canonical key name ("Right", "Shift+Tab", "Period", "L"), the
// name an action ("camera_right"), and the player executes the action.

/// KeyboardEvent.key values whose canonical name (ui/sdl_keys.cpp) is not the key itself.
const NAMES = {
  ArrowLeft: "Left", ArrowRight: "Right", ArrowUp: "Up", ArrowDown: "Down", " ": "Space",
  ".": "Period", ",": "Comma", ">": "Shift+Period", "<": "Shift+Comma",
};

/// Reads keys.json's rows, whatever the outer shape: {bindings: [...]}, {keys: [...]} or [...]; each row
/// {key, action, description} (extra fields kept). Throws Error naming the source and what is wrong.
export function parseKeyTable(json, source = "keys.json") {
  const rows = Array.isArray(json) ? json : json && (json.bindings ?? json.keys);
  if (!Array.isArray(rows) || rows.length === 0) throw new Error(`${source}: no key rows (expected {"bindings": [{"key", "action", "description"}, ...]})`);
  for (const [i, r] of rows.entries())
    if (!r || typeof r.key !== "string" || typeof r.action !== "string")
      throw new Error(`${source}: row ${i} has no string "key" and "action"`);
  const byKey = new Map(rows.map((r) => [r.key, r]));
  return { rows, byKey, raw: json };
}

/// The canonical key name of a keydown event (as ui::key_name: Shift+ prefixed when the table has such
/// a row), or "" for keys without one.
export function keyName(e, table) {
  let name = NAMES[e.key] ?? (e.key.length === 1 ? e.key.toUpperCase() : e.key);
  if (e.shiftKey && !name.startsWith("Shift+") && table && table.byKey.has("Shift+" + name)) name = "Shift+" + name;
  return name;
}

/// The row of a keydown event in the table, or undefined.
export function bindingOf(e, table) {
  if (!table || e.ctrlKey || e.metaKey || e.altKey) return undefined;
  return table.byKey.get(keyName(e, table));
}

/// Key names as a person reads them.
const SHOWN = { Left: "←", Right: "→", Up: "↑", Down: "↓", Period: ".", Comma: ",", "Shift+Period": ">", "Shift+Comma": "<",
                PageUp: "PgUp", PageDown: "PgDn" };
const shown = (k) => SHOWN[k] ?? k;

/// The help rows for the database at hand: [{keys, text}], keys of one action joined ("H, F1").
/// `kind` is "flat", "360" (look around) or "walk" (look around and walk); a row's description is
/// the table's `descriptions[kind]` when keys.json gives one, else `description`. Rows whose action
/// the player cannot do here (`unsupported`, a Set of action names) are left out.
export function helpRows(table, kind, unsupported = new Set()) {
  const out = [], byAction = new Map();
  for (const r of table.rows) {
    if (unsupported.has(r.action)) continue;
    const text = (r.descriptions && r.descriptions[kind]) ?? r.description ?? r.action;
    const prev = byAction.get(r.action);
    // Rows of one action with the same wording share a line; digit keys 2..9 fold into "1".
    if (prev && (prev.text === text || /^task_[2-9]$/.test(r.action))) { prev.keys.push(shown(r.key)); continue; }
    if (/^task_[2-9]$/.test(r.action) && byAction.has("task_1")) continue;
    const row = { keys: [shown(r.key)], text, action: r.action };
    byAction.set(r.action, row);
    out.push(row);
  }
  return out.map((r) => ({ keys: r.keys.join(", "), text: r.text, action: r.action }));
}
