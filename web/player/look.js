// Looking around inside 360° (equirectangular) streams and walking between lattice cameras: a line
// for line port of the desktop's rules in src/player/look.cpp (Look, camera_basis, look_basis,
// look_towards, walk_target), so that a key walks to the same camera in the browser as in
// `panoptes play` and `play --headless`. Vectors are [x, y, z] arrays in world coordinates.
const DEG = Math.PI / 180;
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const normalize = (a) => scale(a, 1 / norm(a));

/// C's remainder(): x − n·y with n the integer nearest x/y (ties to even).
function remainder(x, y) {
  const q = x / y;
  let n = Math.round(q);
  if (Math.abs(q - Math.trunc(q)) === 0.5) n = 2 * Math.round(q / 2);  // ties to even, as C
  return x - n * y;
}

/// The look's limits: player::clamped's, replaced by keys.json's `look` block when it is loaded.
export const LOOK_LIMITS = { pitch_max_deg: 89, fov_min_deg: 20, fov_max_deg: 120 };
/// The look's range, as player::clamped: pitch within ±89°, field of view 20°..120°, yaw in (−180°, 180°].
export function clamped(l, limits = LOOK_LIMITS) {
  const out = {
    yaw: remainder(l.yaw, 360),
    pitch: Math.min(limits.pitch_max_deg, Math.max(-limits.pitch_max_deg, l.pitch)),
    fov: Math.min(limits.fov_max_deg, Math.max(limits.fov_min_deg, l.fov)),
  };
  if (out.yaw === -180) out.yaw = 180;
  return out;
}

/// The frame {forward, right, up} of a camera (position, lookAt, up), as player::camera_basis.
export function cameraBasis(position, lookAt, up) {
  const d = sub(lookAt, position);
  if (!(norm(d) > 0)) return { forward: [0, 1, 0], right: [1, 0, 0], up: [0, 0, 1] };
  const forward = normalize(d);
  let u = up;
  if (norm(u) === 0 || norm(cross(forward, normalize(u))) < 1e-6) {
    const ax = Math.abs(forward[0]), ay = Math.abs(forward[1]), az = Math.abs(forward[2]);
    u = az <= ax && az <= ay ? [0, 0, 1] : ay <= ax ? [0, 1, 0] : [1, 0, 0];
  }
  const right = normalize(cross(forward, u));
  return { forward, right, up: cross(right, forward) };
}

/// The frame after turning by the look's yaw (about the camera's up), then its pitch.
export function lookBasis(c, l) {
  const cy = Math.cos(l.yaw * DEG), sy = Math.sin(l.yaw * DEG);
  const cp = Math.cos(l.pitch * DEG), sp = Math.sin(l.pitch * DEG);
  const heading = add(scale(c.forward, cy), scale(c.right, sy));
  const right = sub(scale(c.right, cy), scale(c.forward, sy));
  const forward = add(scale(heading, cp), scale(c.up, sp));
  return { forward, right, up: cross(right, forward) };
}

/// The look of a camera (frame c) facing the world direction d, with field of view fov.
export function lookTowards(c, d, fov) {
  const x = dot(d, c.right), y = dot(d, c.up), z = dot(d, c.forward);
  return clamped({ yaw: Math.atan2(x, z) / DEG, pitch: Math.atan2(y, Math.hypot(x, z)) / DEG, fov });
}

/// The manifest's rig: {equirect, lattice: [nx, ny, nz] or null, path}. As player::is_equirectangular
/// and player::lattice_shape (a shape that does not match the camera count is not trusted).
export function rigOf(manifest, cameraCount) {
  const p = (manifest && manifest.rig && manifest.rig.parameters) || {};
  const equirect = p.projection === "equirectangular";
  let lattice = null;
  if (Array.isArray(p.lattice) && p.lattice.length === 3 &&
      p.lattice.every((v) => Number.isInteger(v) && v >= 1 && v <= 1 << 24) &&
      p.lattice[0] * p.lattice[1] * p.lattice[2] === cameraCount)
    lattice = p.lattice.slice();
  return { equirect, lattice, path: p.path === true, walkable: equirect && (lattice !== null || p.path === true) };
}

/// Lattice node [i, j, k] of a camera id (i fastest), as player::lattice_node.
export function latticeNode(shape, c) {
  if (!shape || shape[0] < 1 || shape[1] < 1 || c < 0) return [0, 0, 0];
  return [c % shape[0], Math.floor(c / shape[0]) % shape[1], Math.floor(c / (shape[0] * shape[1]))];
}

const vec = (cams, column, c) => [cams[column][3 * c], cams[column][3 * c + 1], cams[column][3 * c + 2]];
/// The frame of camera c of the player's camera columns (cameras.js).
export function basisOfCamera(cams, c) {
  return cameraBasis(vec(cams, "position", c), vec(cams, "look_at", c), vec(cams, "up", c));
}
export const positionOf = (cams, c) => vec(cams, "position", c);

/// The six walks, named as player::Walk.
export const WALKS = ["forward", "back", "left", "right", "up", "down"];

/// The neighbour of `camera` (any of its six graph slots) whose displacement is best aligned with the
/// walk's world direction (angle below 60°), or −1: player::walk_target.
export function walkTarget(cams, camera, look, walk, minCos = 0.5) {
  if (!cams || !cams.neighbours || camera < 0 || camera >= cams.count) return -1;
  const here = positionOf(cams, camera);
  const cam = basisOfCamera(cams, camera);
  const view = lookBasis(cam, look);
  const d = { forward: view.forward, back: scale(view.forward, -1), right: view.right, left: scale(view.right, -1),
              up: cam.up, down: scale(cam.up, -1) }[walk];
  return bestAligned(cams, camera, here, d, 1, minCos);  // cos 60°: never walk sideways when nothing lies ahead
}

/// The graph neighbour of `camera` (at `here`) whose displacement makes the largest cosine above minCos
/// with d (of length lenD), or −1.
function bestAligned(cams, camera, here, d, lenD, minCos) {
  let best = -1, bestCos = minCos;
  for (let s = 0; s < 6; s++) {
    const id = cams.neighbours[6 * camera + s];
    if (id < 0 || id >= cams.count || id === camera) continue;
    const step = sub(positionOf(cams, id), here);
    const len = norm(step);
    if (!(len > 0)) continue;
    const c = dot(step, d) / (len * lenD);
    if (c > bestCos) { bestCos = c; best = id; }
  }
  return best;
}

/// The look at camera `to` that keeps the world view direction of `look` at camera `from`
/// (player::walk_keeping_view).
export function lookAfterWalk(cams, from, to, look) {
  const view = lookBasis(basisOfCamera(cams, from), look);
  return lookTowards(basisOfCamera(cams, to), view.forward, look.fov);
}

/// The world view direction of a look at camera c.
export function viewDirection(cams, c, look) {
  return lookBasis(basisOfCamera(cams, c), look).forward;
}

/// "look yaw -90  pitch +13  fov 60", as the desktop HUD (ui::look_text).
export function lookText(l) {
  const signed = (v) => {
    const r = Math.round(v);
    return r === 0 ? "0" : (r > 0 ? "+" : "") + r;
  };
  return `look yaw ${signed(l.yaw)}  pitch ${signed(l.pitch)}  fov ${Math.round(l.fov)}`;
}

/// The world direction through point (x, y) of a w × h perspective cut-out `look` of a camera with frame
/// `cam` (the cut-out's mapping; the centre is the view's forward): player::cutout_direction.
export function cutoutDirection(cam, look, x, y, w, h) {
  const v = lookBasis(cam, look);
  const tanHalf = Math.tan((look.fov * Math.PI) / 360), aspect = h > 0 ? w / h : 1;
  const sx = (2 * x / w - 1) * tanHalf * aspect, sy = (1 - 2 * y / h) * tanHalf;
  return normalize(add(add(v.forward, scale(v.right, sx)), scale(v.up, sy)));
}

/// The graph neighbour of `camera` whose displacement is best aligned with the world direction d
/// (angle below 60°, as walking), or −1: player::neighbour_toward (double-click to step).
export function neighbourToward(cams, camera, d) {
  if (!cams || !cams.neighbours || camera < 0 || camera >= cams.count) return -1;
  const lenD = norm(d);
  if (!(lenD > 0)) return -1;
  return bestAligned(cams, camera, positionOf(cams, camera), d, lenD, 0.5);
}

/// The world direction of the strongest signal in an equirectangular frame (luma: W × H bytes, rows
/// from the top) seen from a camera with frame `cam`, or null: player::strongest_signal_direction, line
/// for line — the solid-angle weighted mean direction of the pixels in the top 2 % of luma and at least
/// 16 levels above the median, weighted by how far above the median; null when nothing stands out or
/// the bright pixels surround the camera evenly.
export function strongestSignalDirection(luma, W, H, cam) {
  if (W < 2 || H < 2 || luma.length < W * H) return null;
  const hist = new Float64Array(256);
  let total = 0;
  for (let y = 0; y < H; y++) {
    const w = Math.cos((0.5 - (y + 0.5) / H) * Math.PI);
    for (let x = 0; x < W; x++) hist[luma[y * W + x]] += w;
    total += w * W;
  }
  let median = 0, top = 255, acc = 0;
  for (let v = 0; v < 256; v++) {
    acc += hist[v];
    if (acc < 0.5 * total) median = v + 1;
    if (acc < 0.98 * total) top = v + 1;
  }
  const threshold = Math.max(top, median + 16);
  if (threshold > 255) return null;
  let sum = [0, 0, 0], weight = 0;
  for (let y = 0; y < H; y++) {
    const lat = (0.5 - (y + 0.5) / H) * Math.PI, cl = Math.cos(lat), sl = Math.sin(lat);
    for (let x = 0; x < W; x++) {
      const l = luma[y * W + x];
      if (l < threshold) continue;
      const lon = (2 * (x + 0.5) / W - 1) * Math.PI;
      const w = (l - median) * cl;
      sum = add(sum, scale(add(add(scale(cam.forward, cl * Math.cos(lon)), scale(cam.right, cl * Math.sin(lon))), scale(cam.up, sl)), w));
      weight += w;
    }
  }
  if (!(weight > 0) || norm(sum) < 0.2 * weight) return null;
  return normalize(sum);
}
