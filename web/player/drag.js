// Mouse-drag rotation, the same maths as the desktop player (src/ui/drag_rotation.cpp): the drag
// turns a virtual viewing direction around the rig centre ("grab the object": dragging right turns
// the object's front to the right), and the player snaps to the camera nearest that direction.
export const DEGREES_PER_HEIGHT = 180;

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const normalize = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));

/// Rotates v about the unit axis by angle (radians, right-handed; Rodrigues' formula).
export function rotate(v, axis, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(scale(v, c), scale(cross(axis, v), s)), scale(axis, dot(axis, v) * (1 - c)));
}

export class DragRotation {
  begin(position, up, center) {
    this.dir = normalize(sub(position, center));
    let u = sub(up, scale(this.dir, dot(up, this.dir)));
    if (Math.hypot(...u) < 1e-9)
      u = Math.abs(this.dir[2]) < 0.9 ? sub([0, 0, 1], scale(this.dir, this.dir[2])) : sub([1, 0, 0], scale(this.dir, this.dir[0]));
    this.up = normalize(u);
    this.active = true;
  }
  move(dx, dy, viewportHeight) {
    if (!this.active || viewportHeight <= 0) return;
    const perPixel = (DEGREES_PER_HEIGHT / viewportHeight) * (Math.PI / 180);
    const right = normalize(cross(scale(this.dir, -1), this.up));
    if (dx !== 0) this.dir = normalize(rotate(this.dir, this.up, -dx * perPixel));
    if (dy !== 0) {
      this.dir = normalize(rotate(this.dir, right, -dy * perPixel));
      this.up = rotate(this.up, right, -dy * perPixel);
    }
    this.up = normalize(sub(this.up, scale(this.dir, dot(this.up, this.dir))));
  }
  end() { this.active = false; }
}

/// Unit directions (look-at → camera) of every camera, from the column arrays of database.json.
export function cameraDirections(cameras) {
  const n = cameras.count, dirs = new Float64Array(3 * n);
  const at = (col, i, k) => (col.length === 3 ? col[k] : col[3 * i + k]);
  for (let i = 0; i < n; i++) {
    const d = normalize([0, 1, 2].map((k) => at(cameras.position, i, k) - at(cameras.look_at, i, k)));
    dirs.set(d, 3 * i);
  }
  return dirs;
}

/// The camera of `shell` whose direction is nearest `dir` (largest dot product); -1 if none.
export function nearestCamera(dirs, shells, dir, shell) {
  let best = -1, bestDot = -Infinity;
  for (let i = 0; i < shells.length; i++) {
    if (shells[i] !== shell) continue;
    const d = dirs[3 * i] * dir[0] + dirs[3 * i + 1] * dir[1] + dirs[3 * i + 2] * dir[2];
    if (d > bestDot) { bestDot = d; best = i; }
  }
  return best;
}
