// The value under the cursor of a slice task (issue 41), as the desktop window shows it. The colour
// table, the slice's plane and the rule's thresholds come from database.json (tasks[i].readout and the
// readout_tables entry it names, written from src/player/value_readout.cpp's slice_readout_json); this file only searches them, line for line as
// read_colour() and pixel_on_slice() there, and scales by the frame's window as the legend does.
import { taskLegend, legendNumber } from "./legend.js";

const dist = (c, rgb) => Math.hypot(c[0] - rgb[0], c[1] - rgb[1], c[2] - rgb[2]);

/// {kind: "value"|"below"|"above"|"none", value, resolution, reason} for colour `rgb` ([r, g, b], 0..255)
/// of task `t` at `frame`; null when the task has no readout (not a slice).
export function readColour(db, t, frame, rgb) {
  const task = db.tasks[t], R = task && task.readout;
  const bar = R && taskLegend(db, t, frame)[0];
  if (!R || !bar || bar.isovalue) return null;
  const T = db.readout_tables && db.readout_tables[R.table];  // shared by tasks with the same map
  if (!T) return null;
  const cs = T.colours, u = T.u;
  const resolution = Math.abs(bar.hi - bar.lo) / cs.length;
  let best = 0, dbest = dist(cs[0], rgb);
  for (let i = 1; i < cs.length; i++) { const d = dist(cs[i], rgb); if (d < dbest) { dbest = d; best = i; } }
  const out = { kind: "none", value: 0, resolution, uncertainty: R.uncertainty_steps * resolution, distance: dbest, reason: "", bar };
  if (dbest > R.max_distance) return { ...out, reason: "not a colour of the map" };
  let umin = u[best], umax = umin;
  for (let i = 0; i < cs.length; i++)
    if (dist(cs[i], rgb) <= dbest + R.margin) { umin = Math.min(umin, u[i]); umax = Math.max(umax, u[i]); }
  if (umax - umin > R.max_spread) return { ...out, reason: "ambiguous colour" };
  if (best === 0) return { ...out, kind: "below", value: bar.lo };
  if (best === cs.length - 1) return { ...out, kind: "above", value: bar.hi };
  let su = 0, n = 0;  // the mean position of the colours within centroid_band of the best (read_colour)
  for (let i = 0; i < cs.length; i++) if (dist(cs[i], rgb) <= dbest + R.centroid_band) { su += u[i]; n++; }
  return { ...out, kind: "value", value: bar.lo + (su / n) * (bar.hi - bar.lo) };
}

// Camera::fallback_up (src/camera/camera.cpp): the world axis least aligned with the view.
function fallbackUp(f) {
  const a = f.map(Math.abs);
  return a[2] <= a[0] && a[2] <= a[1] ? [0, 0, 1] : a[1] <= a[0] ? [0, 1, 0] : [1, 0, 0];
}
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const unit = (a) => { const n = norm(a); return n > 0 ? a.map((x) => x / n) : a; };

/// True when the ray through the centre of pixel (x, y) of camera `c` meets the slice plane inside the
/// domain box (pixel_on_slice); true when the box or the camera's field of view is not known.
export function pixelOnSlice(db, cams, t, c, x, y) {
  const R = db.tasks[t].readout;
  if (!R.box_lo || !cams || !cams.fov_y_deg) return true;
  const col = (name) => [0, 1, 2].map((k) => cams[name][3 * c + k]);
  const pos = col("position"), f = unit(sub(col("look_at"), pos));
  let up = col("up");
  if (norm(up) === 0 || norm(cross(f, unit(up))) < 1e-6) up = fallbackUp(f);
  const right = unit(cross(f, up)), u = cross(right, f);
  const W = db.image.width, H = db.image.height, tanHalf = Math.tan((cams.fov_y_deg[c] * Math.PI) / 360);
  const sx = ((2 * (x + 0.5)) / W - 1) * tanHalf * (W / H), sy = (1 - (2 * (y + 0.5)) / H) * tanHalf;
  const d = [0, 1, 2].map((k) => f[k] + right[k] * sx + u[k] * sy);
  const a = R.axis;
  if (d[a] === 0) return false;
  const s = (R.position - pos[a]) / d[a];
  if (!(s > 0)) return false;
  for (let b = 0; b < 3; b++) {
    if (b === a) continue;
    const p = pos[b] + d[b] * s, slack = 1e-9 * (R.box_hi[b] - R.box_lo[b]);
    if (p < R.box_lo[b] - slack || p > R.box_hi[b] + slack) return false;
  }
  return true;
}

/// read_pixel(): the reading of pixel (x, y) of camera c's frame with colour rgb; null without a readout.
export function readPixel(db, cams, t, frame, c, x, y, rgb) {
  const r = readColour(db, t, frame, rgb);
  if (r && !pixelOnSlice(db, cams, t, c, x, y)) return { ...r, kind: "none", reason: "off the slice" };
  return r;
}

/// As reading_text(): "phi = 1.23e-05 1/s  (+-8.4e-07)", "phi <= -1.2e-04 1/s", "no reading: off the slice".
export function readingText(r) {
  if (r.kind === "none") return `no reading: ${r.reason}`;
  const b = r.bar, unit = b.physical && b.units ? ` ${b.units}` : "", rel = b.physical ? "" : " x reference";
  if (r.kind === "below") return `${b.label} <= ${legendNumber(r.value)}${unit}${rel}`;
  if (r.kind === "above") return `${b.label} >= ${legendNumber(r.value)}${unit}${rel}`;
  return `${b.label} = ${legendNumber(r.value)}${unit}${rel}  (+-${legendNumber(r.uncertainty)})`;
}
