// The cameras as the player uses them: column-wise typed arrays (lat_deg, lon_deg, shell, position,
// look_at, up: 3 per camera) and the navigation graph (neighbours: 6 per camera, -1 = none), read
// either from the database's binary camera table (docs/formats.md, "Camera table"), fetched as it is
// from the server — its per-camera columns become typed-array views without a copy — or from the
// inline columns of database.json (schema 1 databases).

const COLUMNS_OFFSET = 40, DESCRIPTOR_BYTES = 56;
const TYPES = { 1: Float64Array, 2: Int32Array, 3: Uint32Array };

/// Parses a camera table file (ArrayBuffer). Throws Error naming `source` and what is wrong.
export function parseCameraTable(buf, source = "camera table") {
  const fail = (what) => { throw new Error(`${source}: ${what}`); };
  if (buf.byteLength < COLUMNS_OFFSET) fail(`${buf.byteLength} bytes, too short for a camera table`);
  const v = new DataView(buf);
  const magic = new TextDecoder().decode(new Uint8Array(buf, 0, 8));
  if (magic !== "PNPTCAMS") fail(`not a camera table (magic "${magic}")`);
  if (v.getUint32(8, true) !== 1) fail(`layout version ${v.getUint32(8, true)} (this player reads 1)`);
  if (Number(v.getBigUint64(16, true)) !== buf.byteLength) fail(`header says ${v.getBigUint64(16, true)} bytes, got ${buf.byteLength}`);
  const n = Number(v.getBigUint64(24, true)), columns = v.getUint32(32, true);
  if (COLUMNS_OFFSET + columns * DESCRIPTOR_BYTES > buf.byteLength) fail(`${columns} column descriptors do not fit`);
  const little = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
  const out = { count: n };
  for (let c = 0; c < columns; c++) {
    const d = COLUMNS_OFFSET + c * DESCRIPTOR_BYTES;
    const name = new TextDecoder().decode(new Uint8Array(buf, d, 24)).replace(/\0+$/, "");
    const type = v.getUint32(d + 24, true), comps = v.getUint32(d + 28, true);
    const rows = Number(v.getBigUint64(d + 32, true)), offset = Number(v.getBigUint64(d + 40, true));
    const size = Number(v.getBigUint64(d + 48, true));
    const T = TYPES[type];
    if (!T) continue;  // blobs (patch names, free-form labels): not needed here
    if (rows !== n && rows !== 1) fail(`column ${name}: ${rows} rows for ${n} cameras`);
    if (size !== rows * comps * T.BYTES_PER_ELEMENT || offset + size > buf.byteLength || offset % T.BYTES_PER_ELEMENT)
      fail(`column ${name}: ${size} bytes at ${offset} do not fit`);
    let a;
    if (little) a = new T(buf, offset, rows * comps);
    else {  // a big-endian machine: decode value by value
      a = new T(rows * comps);
      for (let i = 0; i < a.length; i++) {
        const o = offset + i * T.BYTES_PER_ELEMENT;
        a[i] = type === 1 ? v.getFloat64(o, true) : type === 2 ? v.getInt32(o, true) : v.getUint32(o, true);
      }
    }
    if (rows === 1 && n !== 1) {  // one value shared by every camera (rigs share look_at, up, shell)
      const full = new T(n * comps);
      full.set(a, 0);
      for (let len = comps; len < full.length; len *= 2) full.copyWithin(len, 0, Math.min(len, full.length - len));
      a = full;
    }
    out[name] = a;
  }
  for (const need of ["position", "look_at", "up", "lat_deg", "lon_deg", "shell"])
    if (!out[need]) fail(`no column "${need}"`);
  if (!out.neighbours) out.neighbours = null;
  return out;
}

/// The same from database.json's inline columns and graph rows.
export function camerasFromJson(cameras, graph) {
  const n = cameras.count;
  const out = {
    count: n,
    lat_deg: Float64Array.from(cameras.lat_deg), lon_deg: Float64Array.from(cameras.lon_deg),
    shell: Int32Array.from(cameras.shell), position: Float64Array.from(cameras.position),
    look_at: Float64Array.from(cameras.look_at), up: Float64Array.from(cameras.up), neighbours: null,
  };
  if (graph && graph.length === n) out.neighbours = Int32Array.from(graph.flat());
  return out;
}

const OPPOSITE = { left: "right", right: "left", up: "down", down: "up", in: "out", out: "in" };
const MAX_TRAIL = 256;

/// The players' arrow-key rule (camera::MoveTrail in src/camera/navigation.hpp): a move opposite to
/// the last move(s) retraces them, so Up, Up, Down, Down returns to the start camera even where the
/// navigation graph's pairs are not mutual (around the sky poles); other moves follow the graph.
export class MoveTrail {
  constructor() { this.steps = []; }
  /// Forgets the moves (a drag or a mini-map click is not an arrow move).
  clear() { this.steps.length = 0; }
  /// The camera `move` from `camera` leads to, given the graph's neighbour `graphTarget` (-1 = none).
  next(camera, move, graphTarget) {
    const last = this.steps[this.steps.length - 1];
    if (last && last.to !== camera) this.steps.length = 0;  // moved by other means (drag, mini-map)
    if (last && last.to === camera && last.move === OPPOSITE[move]) return this.steps.pop().from;
    if (graphTarget < 0 || graphTarget === camera) return graphTarget;
    if (this.steps.length === MAX_TRAIL) this.steps.splice(0, MAX_TRAIL / 2);
    this.steps.push({ from: camera, to: graphTarget, move });
    return graphTarget;
  }
  /// Where `move` would lead now without recording it (for prefetching).
  peek(camera, move, graphTarget) {
    const last = this.steps[this.steps.length - 1];
    return last && last.to === camera && last.move === OPPOSITE[move] ? last.from : graphTarget;
  }
}
