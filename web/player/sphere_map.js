// The mini-map of cameras around the data (sphere rigs): every camera by longitude (x) and latitude (y),
// the current shell's bright and the others dim, the graph neighbours in blue, the current camera
// ringed. A click picks the nearest camera. The dots are drawn once per shell into an offscreen canvas
// (10^6 cameras would otherwise be 10^6 fillRects per drawn frame); each frame copies it and adds the marks.

export class SphereMap {
  /// cams: the player's camera columns (lon_deg, lat_deg, shell, count).
  constructor(cams) {
    this.cams = cams;
    this.background = null;
    this.shell = null;
  }
  /// Canvas point of camera i on a w × h map.
  xy(i, w, h) {
    return [((this.cams.lon_deg[i] + 180) / 360) * w, ((90 - this.cams.lat_deg[i]) / 180) * h];
  }
  /// Draws the map; neighbours: the current camera's graph neighbours (-1 for none).
  draw(ctx, w, h, current, neighbours) {
    const cams = this.cams, n = cams.count, shell = cams.shell[current];
    const radius = n > 2000 ? 1 : n > 300 ? 2 : 3;
    if (!this.background || this.shell !== shell || this.background.width !== w || this.background.height !== h) {
      this.background = document.createElement("canvas");
      this.background.width = w;
      this.background.height = h;
      const g = this.background.getContext("2d");
      g.fillStyle = "rgba(10,14,22,0.85)";
      g.fillRect(0, 0, w, h);
      g.strokeStyle = "#334";
      g.beginPath();
      g.moveTo(0, h / 2); g.lineTo(w, h / 2); g.moveTo(w / 2, 0); g.lineTo(w / 2, h);
      g.stroke();
      for (const other of [true, false]) {  // other shells first, under the current one
        g.fillStyle = other ? "#445" : "#9aa";
        for (let i = 0; i < n; i++) {
          if ((cams.shell[i] !== shell) !== other) continue;
          const [x, y] = this.xy(i, w, h);
          g.fillRect(x - radius / 2, y - radius / 2, radius, radius);
        }
      }
      this.shell = shell;
    }
    ctx.clearRect(0, 0, w, h);
    ctx.drawImage(this.background, 0, 0);
    ctx.fillStyle = "#6cf";
    for (const i of neighbours) {
      if (i < 0 || cams.shell[i] !== shell) continue;
      const [x, y] = this.xy(i, w, h);
      ctx.fillRect(x - radius / 2, y - radius / 2, radius, radius);
    }
    const [x, y] = this.xy(current, w, h);
    ctx.strokeStyle = "#ff4";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(x, y, 6, 0, 2 * Math.PI);
    ctx.stroke();
  }
  /// The camera nearest to canvas point (px, py) of a w × h map, or -1.
  pick(px, py, w, h) {
    let best = -1, bestD = Infinity;
    for (let i = 0; i < this.cams.count; i++) {
      const [x, y] = this.xy(i, w, h);
      const d = (x - px) ** 2 + (y - py) ** 2;
      if (d < bestD) { bestD = d; best = i; }
    }
    return best;
  }
}
