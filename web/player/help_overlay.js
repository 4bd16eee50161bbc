// The key help of the web player (H): every key and mouse action of this database in a table over the
// page, as the desktop's help overlay, and a one-line hint under the view. Built from the rows of
// keys.js's helpRows(), so the browser keeps no copy of the key table.

const esc = (t) => String(t).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);

/// Fills `overlay` with the table (mouse: [[what, text]...]; rows: [{keys, text}]) and `hint` with the line
/// that says how to open it.
export function renderHelp(overlay, hint, mouse, rows) {
  const row = (k, t) => `<div class="row"><span class="keys">${esc(k)}</span><span>${esc(t)}</span></div>`;
  overlay.innerHTML = "<h2>Keys and mouse (H closes)</h2><div class=\"rows\">" +
    mouse.map(([k, t]) => row(k, t)).join("") + rows.map((r) => row(r.keys, r.text)).join("") + "</div>";
  hint.textContent = `H: keys and mouse (${rows.length + mouse.length}) · ` + mouse.map(([k, t]) => `${k}: ${t}`).join(" · ");
}
