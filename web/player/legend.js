// Colour legends (issue 34): each bar of the current task — its transfer function's colours and its
// window in physical values and units at the shown frame — as the desktop HUD draws them. The colours
// are the desktop's own (src/player/legend.cpp, drawn_colours): database.json publishes them per task
// as `drawn_colours` (a slice's or a MIP's opaque colour map, a volume's thin layer over black), so the two front
// ends cannot drift apart (issue 41: this file used to recompute them, every task as a volume).

const drawnColours = (task, tfKey) => (task.drawn_colours && task.drawn_colours[tfKey]) || [];

function reference(db, field, frame) {
  const f = (db.fields || []).find((x) => x.name === field);
  const refs = f ? f.references : [];
  return refs.length ? refs[Math.min(Math.max(frame, 0), refs.length - 1)] : 0;
}
const unitsOf = (db, field) => ((db.fields || []).find((x) => x.name === field) || {}).units || "";

// What a field's references follow (as reference_mode() in C++): the manifest's word, or for older
// databases "running" when the session kept running maxima, else "snapshot".
function referenceMode(db, field) {
  const f = (db.fields || []).find((x) => x.name === field);
  if (!f || !(f.references || []).length) return "";
  if (f.reference_mode) return f.reference_mode;
  const extra = (db.provenance && db.provenance.extra) || {};
  return "insitu.running_max" in extra ? "running" : "snapshot";
}

// The reference of a task's window of `field` at `frame`; a shared scale takes the larger of its fields'.
function taskReference(db, fields, field, shared, frame) {
  if (!shared) return reference(db, field, frame);
  let r = 0;
  for (const f of fields) { const v = reference(db, f, frame); if (!(v > 0)) return 0; r = Math.max(r, v); }
  return r;
}

function windowBar(db, task, field, p, windowKey, relativeKey, tfKey, frame) {
  const tf = p[tfKey], fields = task.fields || [];
  const bar = { field, label: tf && tf.absolute_value ? `|${field}|` : field, units: unitsOf(db, field),
                lo: p[windowKey][0], hi: p[windowKey][1], physical: true, isovalue: false, colours: drawnColours(task, tfKey),
                scale: "", shared: false, change: 1 };
  if (p[relativeKey]) {
    bar.shared = fields.length > 1 && p.scale === "shared";
    const ref = taskReference(db, fields, field, bar.shared, frame);
    if (ref > 0) {
      bar.lo *= ref; bar.hi *= ref;
      bar.scale = referenceMode(db, field);
      if (frame > 0) { const before = taskReference(db, fields, field, bar.shared, frame - 1); bar.change = before > 0 ? ref / before : 0; }
    } else bar.physical = false;
  }
  return bar;
}

/// As legend_scale_mode_text() in C++: "running max", "per snapshot, shared with phi_s", ...
export function legendScaleModeText(bar, sharedWith = "") {
  if (!bar.scale) return "";
  let s = bar.scale === "running" ? "running max" : bar.scale === "snapshot" ? "per snapshot" : bar.scale;
  if (bar.shared) s += sharedWith ? `, shared with ${sharedWith}` : ", shared scale";
  return s;
}
/// As legend_change_text(): "x2.3 since the previous frame", "" when the scale did not change.
export function legendChangeText(bar) {
  if (!bar.scale || !(bar.change > 0) || Math.abs(bar.change - 1) < 0.005) return "";
  return `x${Number(bar.change.toPrecision(3))} since the previous frame`;
}
/// As legend_scale_text() in C++: the two joined, "per snapshot: x2.3 since the previous frame".
export function legendScaleText(bar, sharedWith = "") {
  const mode = legendScaleModeText(bar, sharedWith), change = legendChangeText(bar);
  return change ? `${mode}: ${change}` : mode;
}

/// The bars of task `t` at `frame` (see LegendBar in src/player/legend.hpp).
export function taskLegend(db, t, frame) {
  const task = db.tasks[t];
  const p = task && task.parameters, fields = (task && task.fields) || [];
  if (!p || fields.length === 0) return [];
  const pair = (k) => Array.isArray(p[k]) && p[k].length === 2 && p[k].every(Number.isFinite);
  if (pair("window")) {
    const bars = [windowBar(db, task, fields[0], p, "window", "relative", "transfer_function", frame)];
    if (fields.length > 1 && pair("window2")) bars.push(windowBar(db, task, fields[1], p, "window2", "relative2", "transfer_function2", frame));
    return bars;
  }
  if (task.method === "isosurface" && Number.isFinite(p.isovalue)) {
    let v = p.isovalue, physical = true;
    let scale = "", change = 1;
    if (p.relative) {
      const ref = reference(db, fields[0], frame);
      if (ref > 0) {
        v *= ref; scale = referenceMode(db, fields[0]);
        if (frame > 0) { const before = reference(db, fields[0], frame - 1); change = before > 0 ? ref / before : 0; }
      } else physical = false;
    }
    return [{ field: fields[0], label: fields[0], units: unitsOf(db, fields[0]), lo: v, hi: v, physical, isovalue: true,
              colours: Array.isArray(p.colour) && p.colour.length === 3 ? [p.colour] : [], scale, shared: false, change }];
  }
  return [];
}

/// As legend_number() in C++: 3 significant digits, exponent form outside [1e-3, 1e5).
export function legendNumber(v) {
  if (v === 0) return "0";
  if (!Number.isFinite(v)) return "?";
  const a = Math.abs(v);
  if (a >= 1e-3 && a < 1e5) return String(Number(v.toPrecision(3)));
  const [m, e] = v.toExponential(2).split("e");
  return `${m}e${e[0] === "-" ? "-" : "+"}${e.replace(/^[-+]/, "").padStart(2, "0")}`;
}

/// "t = 4.2 s" (as time_text() in C++).
export function timeText(db, t) {
  return `t = ${Number(t.toPrecision(4))}${db.time_units ? " " + db.time_units : ""}`;
}

// The lines under a bar that say what its scale follows (issue 41): the mode, and when the
// reference changed since the previous frame, by what factor (drawn in amber).
function scaleLines(bar, bars) {
  const other = bars.find((o) => o !== bar);
  const mode = legendScaleModeText(bar), change = legendChangeText(bar), lines = [];
  // One phrase a line: the canvas is 240 CSS pixels wide, and the whole text took 60 characters.
  if (mode) {
    const shared = mode.indexOf(", shared");
    lines.push({ text: `scale: ${shared < 0 ? mode : mode.slice(0, shared)}`, changed: false });
    if (shared >= 0) lines.push({ text: other ? `shared with ${other.field}` : "shared scale", changed: false });
  }
  if (change) lines.push({ text: change, changed: true });
  return lines;
}

/// Draws the bars into `canvas` (sized to fit, in CSS pixels × devicePixelRatio); hides it when empty.
export function drawLegend(canvas, bars) {
  canvas.hidden = bars.length === 0;
  if (!bars.length) return;
  const dpr = window.devicePixelRatio || 1, W = 240, rowH = 44, lineH = 14, barW = 200, barH = 12;
  const lines = bars.map((bar) => scaleLines(bar, bars));
  const heights = lines.map((l) => rowH + l.length * lineH);
  const H = heights.reduce((a, b) => a + b, 0) + 4;
  canvas.style.width = `${W}px`;
  canvas.style.height = `${H}px`;
  canvas.width = Math.round(W * dpr);
  canvas.height = Math.round(H * dpr);
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, W, H);
  ctx.font = "12px ui-monospace, monospace";
  ctx.textBaseline = "top";
  let y = 4;
  bars.forEach((bar, i) => {
    const x = 10, top = y;
    y += heights[i];
    ctx.fillStyle = "#e5e9f0";
    ctx.textAlign = "left";
    ctx.fillText(`${bar.label}${bar.physical && bar.units ? `  [${bar.units}]` : ""}`, x, top);
    const rgb = (c) => `rgb(${c.map((v) => Math.round(v * 255)).join(",")})`;
    ctx.font = "11px ui-monospace, monospace";
    lines[i].forEach((l, k) => {
      ctx.fillStyle = l.changed ? "#ffc74d" : "#9ea8bd";
      ctx.textAlign = "left";
      ctx.fillText(l.text, x, top + rowH + k * lineH - (bar.isovalue ? 14 : 0));
    });
    ctx.font = "12px ui-monospace, monospace";
    if (bar.isovalue) {
      if (bar.colours.length) { ctx.fillStyle = rgb(bar.colours[0]); ctx.fillRect(x, top + 15, 24, barH); }
      ctx.fillStyle = "#e5e9f0";
      ctx.fillText(`iso ${legendNumber(bar.lo)}${bar.physical ? "" : " x ref"}`, x + 32, top + 15);
      return;
    }
    if (bar.colours.length) {
      const g = ctx.createLinearGradient(x, 0, x + barW, 0);
      bar.colours.forEach((c, k) => g.addColorStop(k / (bar.colours.length - 1), rgb(c)));
      ctx.fillStyle = g;
      ctx.fillRect(x, top + 15, barW, barH);
      ctx.strokeStyle = "#8c99b3";
      ctx.strokeRect(x + 0.5, top + 15.5, barW - 1, barH - 1);
    }
    ctx.fillStyle = "#e5e9f0";
    ctx.fillText(legendNumber(bar.lo), x, top + 29);
    ctx.textAlign = "right";
    ctx.fillText(`${legendNumber(bar.hi)}${bar.physical ? "" : " x ref"}`, x + barW, top + 29);
  });
}
