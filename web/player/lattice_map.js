// The mini-map of cameras inside the volume (lattice or path rigs): the domain seen from the sky —
// north (world +x, the seismic convention x north, y east, z depth) up, east right — with every
// camera as a dot (the current depth layer bright), the graph neighbours in blue, the current camera
// ringed and the view cone (heading and horizontal field of view) drawn from it. A click picks the
// nearest camera of the current layer.
import { positionOf } from "./look.js";

export class LatticeMap {
  /// cams: the player's camera columns; box: {lo: [x, y, z], hi: [x, y, z]} (the domain) or null.
  constructor(cams, box) {
    this.cams = cams;
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let c = 0; c < cams.count; c++) {
      const p = positionOf(cams, c);
      for (let a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
    }
    if (box) { lo = lo.map((v, a) => Math.min(v, box.lo[a])); hi = hi.map((v, a) => Math.max(v, box.hi[a])); }
    this.lo = lo;
    this.hi = hi;
    this.box = box;
  }
  /// Canvas point of a world point on a w × h map (8 % margin, equal scales on both axes).
  xy(p, w, h) {
    const east = this.hi[1] - this.lo[1] || 1, north = this.hi[0] - this.lo[0] || 1;
    const s = Math.min((w * 0.84) / east, (h * 0.84) / north);
    const cx = w / 2, cy = h / 2, my = (this.lo[1] + this.hi[1]) / 2, mx = (this.lo[0] + this.hi[0]) / 2;
    return [cx + (p[1] - my) * s, cy - (p[0] - mx) * s, s];
  }
  /// Draws the map; view: the world view direction; fovH: the horizontal field of view (degrees).
  draw(ctx, w, h, current, neighbours, view, fovH) {
    const cams = this.cams, here = positionOf(cams, current);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, w, h);
    ctx.fillStyle = "rgba(10,14,22,0.85)";
    ctx.fillRect(0, 0, w, h);
    if (this.box) {
      const [x0, y0] = this.xy(this.box.hi, w, h), [x1, y1] = this.xy(this.box.lo, w, h);
      ctx.strokeStyle = "#4c566a";
      ctx.lineWidth = 1;
      ctx.strokeRect(Math.min(x0, x1), Math.min(y0, y1), Math.abs(x1 - x0), Math.abs(y1 - y0));
    }
    const layer = (c) => Math.abs(positionOf(cams, c)[2] - here[2]) < 1e-9 * (1 + Math.abs(here[2]));
    for (const same of [false, true])
      for (let c = 0; c < cams.count; c++) {
        if (layer(c) !== same) continue;
        const [x, y] = this.xy(positionOf(cams, c), w, h);
        ctx.fillStyle = same ? "#9aa" : "#445";
        ctx.fillRect(x - 2, y - 2, 4, 4);
      }
    ctx.fillStyle = "#6cf";
    for (const c of neighbours) {
      const [x, y] = this.xy(positionOf(cams, c), w, h);
      ctx.fillRect(x - 3, y - 3, 6, 6);
    }
    const [x, y] = this.xy(here, w, h);
    // The view cone: the heading (view direction without its vertical part) ± half the field of view.
    const heading = Math.atan2(view[1], view[0]);  // from north towards east
    const half = Math.min(89, fovH / 2) * (Math.PI / 180), r = Math.min(w, h) * 0.28;
    const at = (a) => [x + Math.sin(a) * r, y - Math.cos(a) * r];
    if (Math.hypot(view[0], view[1]) > 1e-6) {
      ctx.fillStyle = "rgba(255,230,80,0.28)";
      ctx.strokeStyle = "#ff4";
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      ctx.moveTo(x, y);
      for (let k = 0; k <= 16; k++) ctx.lineTo(...at(heading - half + (2 * half * k) / 16));
      ctx.closePath();
      ctx.fill();
      ctx.stroke();
    }
    ctx.strokeStyle = "#ff4";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(x, y, 6, 0, 2 * Math.PI);
    ctx.stroke();
    ctx.fillStyle = "#d8dee9";
    ctx.font = "11px sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    ctx.fillText("N", w / 2, 2);
  }
  /// The camera of the current camera's depth layer nearest the canvas point (px, py), or −1.
  pick(px, py, w, h, current) {
    const here = positionOf(this.cams, current);
    let best = -1, bestD = Infinity;
    for (let c = 0; c < this.cams.count; c++) {
      const p = positionOf(this.cams, c);
      if (Math.abs(p[2] - here[2]) > 1e-9 * (1 + Math.abs(here[2]))) continue;
      const [x, y] = this.xy(p, w, h);
      const d = (x - px) ** 2 + (y - py) ** 2;
      if (d < bestD) { bestD = d; best = c; }
    }
    return best;
  }
}
