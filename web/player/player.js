// The Panoptes web player: the same navigation as the desktop player (docs/player.md, docs/ui.md)
// over `panoptes serve` or a static export. Decoding: WebCodecs + mp4box.js (movies.js). Prefetch:
// the current stream and every neighbour are kept decoded a few frames past the playhead, in step
// with playback (pump() below), so a switch finds its frame decoded.
// Sections (each marked "// --- name ---" below):
//   state       imports, the page's elements, the player's state S, streams
//   clock       time stays continuous through switches (engine_ops.js, as player::Engine's)
//   navigation  graph neighbours and select()
//   prefetch    the pump that keeps every reachable stream decoded ahead (prefetch.js)
//   drawing     placeholders, the flat or 360° picture, the frame loop
//   hud         the heads-up text (hud.js) and legend
//   readout     the value under the cursor of a slice task (readout_hover.js, issue 41)
//   minimap     sphere_map.js around the data, lattice_map.js inside it; a click picks a camera
//   input       keys (keys.json: the engine's operations and the page's OPS), wheel, drag, help
//   start       the key table, the mode, the mini-map, main()

// --- state ---
import { FrameCache, Stream, traffic, mark } from "./movies.js";
import { DragRotation, cameraDirections, nearestCamera } from "./drag.js";
import { camerasFromJson, parseCameraTable, MoveTrail } from "./cameras.js";
import { taskLegend, drawLegend, timeText } from "./legend.js";
import { installReadoutHover } from "./readout_hover.js";
import { parseKeyTable, bindingOf, helpRows, operationOf, refusalOf } from "./keys.js";
import { renderHelp } from "./help_overlay.js";
import { makePrefetch } from "./prefetch.js";
import { hudText } from "./hud.js";
import { makeClock, stepTaskOnAxis, engineOps, isFrontEndOperation } from "./engine_ops.js";
import { LOOK_LIMITS, basisOfCamera, clamped, rigOf, latticeNode, walkTarget, lookAfterWalk, viewDirection, lookText, positionOf,
         lookTowards, cutoutDirection, neighbourToward, strongestSignalDirection } from "./look.js";
import { LookView, drawOrientationMarks } from "./look_view.js";
import { LatticeMap } from "./lattice_map.js";
import { SphereMap } from "./sphere_map.js";
import { installTestApi } from "./test_api.js";
import { lateFrame } from "./late_frame.js";

const params = new URLSearchParams(location.search);
const base = new URL(".", location.href).href.split("?")[0];
const options = {
  prefetch: params.get("prefetch") !== "0",
  autoplay: params.get("play") !== "0",
  cacheFrames: Number(params.get("cache") || 240),
  connections: Number(params.get("connections") || 6),  // pump fetches at once (a browser's per-host limit)
  batch: Number(params.get("batch") || 8),  // frames fetched and decoded per range request
  nbBatch: Number(params.get("nbbatch") || 4),  // the same for a neighbour's prefetch
  ahead: Number(params.get("ahead") || 6),  // frames past the playhead kept decoded, current stream
  nbAhead: Number(params.get("nbahead") || 3),  // the same for every neighbour
  // A playing neighbour of keyframes only: "switch" = samples fetched ahead, decoder configured, the
  // one frame the playhead needs decoded when a switch comes to it; "ahead" = decoded ahead like any
  // neighbour, at every nbstride-th frame.
  nbDecode: params.get("nbdecode") === "switch" ? "switch" : "ahead",  // idle 2-core: ahead p99 41 ms, switch 87 ms (docs/web.md)
  nbStride: Number(params.get("nbstride") || 2),  // nbdecode=ahead: every stride-th frame decoded
  abortOnSwitch: params.get("abort") !== "0",  // a switch drops the old stream's decodes (nbdecode=switch)
  switchBatch: Number(params.get("switchbatch") || 1),  // the first batch of a switch's new stream: its first frame alone
  fetchAhead: Number(params.get("fetchahead") || 16),  // frames past the playhead whose bytes are fetched
  warmTasks: params.get("warmtasks") !== "0",  // fetch ahead the graph neighbours of the task neighbours
  // Until a switch is on screen the pump serves the new current stream only: the new neighbours'
  // decoders are created and their decodes started at the display frame that shows the switch, not
  // between the key and that frame (~3 decoders per switch, up to 11 ms of main thread; docs/web.md round 5).
  switchFirst: params.get("switchfirst") !== "0",
  releaseOnKey: params.get("release") === "key",  // close cold decoders in the key's handler (before round 5)
  // An input whose frame is decoded draws in its handler rather than at the next rAF. Measured slower
  // (walks in a lattice, load 14-16: p50 39.5 ms vs 23 ms from the input event; docs/web.md): off.
  drawOnInput: params.get("drawoninput") === "1",
};

const canvas = document.getElementById("view");
const ctx = canvas.getContext("2d");
// 360° databases: the cut-out is drawn by WebGL2 into its own canvas (a canvas has one context kind).
const lookCanvas = document.getElementById("look");
const marksCanvas = document.getElementById("marks");  // orientation marks over the cut-out
let lookView = null;
const hud = document.getElementById("hud");
const legendCanvas = document.getElementById("legend");
const statusLine = document.getElementById("status");
const minimap = document.getElementById("minimap");
const mapCtx = minimap.getContext("2d");

const cache = new FrameCache(options.cacheFrames);
// Diagnostics: when the first decoded frame of a pending switch's stream arrived (ms after the key).
cache.onPut = (key) => {
  const p = S.pending;
  if (p && p.diag.decodedMs === undefined && key.startsWith(`${S.camera}/${S.task}/`)) {
    p.diag.decodedMs = performance.now() - p.t0;
    const st = streams.get(`${S.camera}/${S.task}`);
    if (st && st.decodeCalled >= p.t0) p.diag.decodeCalledMs = st.decodeCalled - p.t0;  // when its decode() was called
  }
};
const streams = new Map();  // "c/t" → Stream, LRU
let inputEventTime = 0;  // timeStamp of the input event being handled (keys, clicks, drags), for select()
const MAX_STREAMS = 96;  // the neighbours and their neighbours (opened ahead) stay open
const drag = new DragRotation();

const S = {
  db: null, cams: null, camera: 0, task: 0, axis: 0,
  playing: options.autoplay, loop: true, speed: 1, dir: 1,
  rig: { equirect: false, lattice: null, path: false, walkable: false },
  look: { yaw: 0, pitch: 0, fov: 90 }, lookDirty: false,
  keys: null,         // the key table (keys.js), null until api/keys.json is in (or when it failed)
  mode: "sphere",     // the key table's mode for this database: sphere, panorama or lattice
  hudHidden: false,
  anchorFrame: 0, anchorTime: 0,
  zoom: 1, panX: 0, panY: 0,
  shown: null,        // {camera, task, frame, status} last drawn
  pending: null,      // switch waiting to be shown: {t0, command, from}
  switches: [],       // {command, from, to, ms, hit}
  firstFrameMs: null,
  firstShown: null,  // what the first drawn frame showed ({camera, task, frame, status})
  message: "",
};

function stream(camera, task) {
  const key = `${camera}/${task}`;
  let s = streams.get(key);
  if (s) { streams.delete(key); streams.set(key, s); return s; }
  s = new Stream(base, S.db, camera, task);
  streams.set(key, s);
  while (streams.size > MAX_STREAMS) {
    const [k, old] = streams.entries().next().value;
    streams.delete(k);
    old.close();
  }
  return s;
}

// --- clock ---
const { currentFrame, setFrame, setPlaying } = makeClock(S);

// --- navigation ---
const COLUMNS = ["left", "right", "up", "down", "in", "out"];
const trail = new MoveTrail();  // the arrow keys' moves, so the opposite key retraces them
function graphNeighbour(camera, direction) {
  const g = S.cams && S.cams.neighbours;  // null until the camera table is loaded, or without a graph
  return g && camera >= 0 && camera < S.cams.count ? g[6 * camera + COLUMNS.indexOf(direction)] : -1;
}
function neighbourSelections(camera, task) {
  const out = [];
  for (const dir of COLUMNS) {
    // The current camera's moves go where the keys lead (a retrace returns to the previous camera).
    const c = camera === S.camera ? trail.peek(camera, dir, graphNeighbour(camera, dir)) : graphNeighbour(camera, dir);
    if (c >= 0) out.push([c, task]);
  }
  const T = S.db.tasks.length;
  if (T > 1) out.push([camera, (task + 1) % T], [camera, (task + T - 1) % T]);
  for (const axis of S.db.axes)
    for (const d of [1, -1]) {
      const t = stepTaskOnAxis(S.db, task, axis.name, d);
      if (t >= 0) out.push([camera, t]);
    }
  const seen = new Set();
  return out.filter(([c, t]) => !(c === camera && t === task) && !seen.has(`${c}/${t}`) && seen.add(`${c}/${t}`));
}

function select(camera, task, command) {
  const eventTime = inputEventTime;  // used once: a refused select must not leave it to a later one
  inputEventTime = 0;
  if (camera < 0 || task < 0 || camera >= S.db.cameras.count || task >= S.db.tasks.length) return false;
  if (camera === S.camera && task === S.task) return false;
  // A switch not yet on screen when the next one comes is recorded as superseded (never shown).
  if (S.pending) S.switches.push({ command: S.pending.command, from: S.pending.from, to: [S.camera, S.task], ms: null, hit: false, superseded: true, diag: S.pending.diag });
  // Why a switch waits (benchmark diagnostics): the target stream's state when the key came.
  const f = currentFrame(), st = streams.get(`${camera}/${task}`);
  const diag = {
    stream: st ? st.status : "closed",
    frameReady: cache.has(`${camera}/${task}/${f}`),
    nextReady: cache.has(`${camera}/${task}/${(f + 1) % S.db.frames}`),
    inflight: st ? st.inflight.size : 0,
    samples: st ? st.hasSamples(f) : false,  // the playhead's compressed frame in memory
    warm: !!(st && st.decoder && st.decoder.state === "configured"),
    maxTickGap: 0,
  };
  // The switch's clock starts at the input event's own timeStamp (same time base as performance.now()):
  // the time the event waited for the main thread is part of what the user waits for (issue 30).
  const th = performance.now(), t0 = eventTime > 0 && eventTime <= th ? eventTime : th;
  diag.keyQueuedMs = th - t0;  // 0 for the API
  diag.at = t0;
  // demux0, output0, warm0: main-thread time on demuxing, decoder outputs and decoder creation from the key to the first display frame.
  S.pending = { t0, command, from: [S.camera, S.task], diag, demux0: traffic.demuxMs, output0: traffic.outputMs, warm0: traffic.warmMs, warms0: traffic.warms };
  const old = streams.get(`${S.camera}/${S.task}`);
  if (options.nbDecode === "switch" && options.abortOnSwitch && S.playing && old && old.status === "ok" && old.intraOnly()) old.abortDecodes();
  S.camera = camera;
  S.task = task;
  // Closing a VideoDecoder costs the main thread several ms (5 of them took 35 ms of a switch's key
  // handler at load 14): done after the switch is drawn, one per display frame (tick), unless
  // ?release=key (the old place, for comparison).
  const closed = options.releaseOnKey ? releaseDecoders() : 0;
  S.releaseDue = true;
  const t1 = performance.now();
  pump();
  diag.selectMs = performance.now() - th;
  diag.releaseMs = t1 - th;
  diag.closed = closed;
  return true;
}

// --- prefetch ---
// prefetch.js: the pump that keeps the current stream and every neighbour decoded ahead of the playhead.
const { pump, releaseDecoders } = makePrefetch({ S, options, cache, streams, stream, currentFrame, neighbourSelections });

// --- drawing ---
function drawPlaceholder(camera, task, status, message) {
  showSurface("flat");
  const w = canvas.width, h = canvas.height;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = "#4a0d0d";
  ctx.fillRect(0, 0, w, h);
  const b = Math.max(3, Math.round(Math.min(w, h) / 60));
  ctx.strokeStyle = "#f2c500";
  ctx.lineWidth = b;
  ctx.strokeRect(b / 2, b / 2, w - b, h - b);
  ctx.fillStyle = "#f2c500";
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  ctx.font = `bold ${Math.round(Math.min(w, h) / 9)}px sans-serif`;
  ctx.fillText(`STREAM ${status.toUpperCase()}`, w / 2, h / 2 - h / 10);
  ctx.font = `${Math.round(Math.min(w, h) / 18)}px sans-serif`;
  ctx.fillText(`camera ${camera} · task ${task + 1}`, w / 2, h / 2 + h / 12);
  S.message = message;
}
/// Which canvas is shown: "flat" (the 2-D canvas: flat frames, placeholders) or "look" (the 360° cut-out).
let surface = "flat";
function showSurface(which) {
  if (which === surface) return;
  surface = which;
  canvas.hidden = which !== "flat";
  lookCanvas.hidden = marksCanvas.hidden = which !== "look";
}
/// The orientation marks' world for the current camera (?marks=0, or before the cameras are in: none).
function lookScene() {
  if (!S.cams || !S.domainBox || params.get("marks") === "0") return null;
  return { basis: basisOfCamera(S.cams, S.camera), position: positionOf(S.cams, S.camera), box: S.domainBox, sky: S.sky, north: [1, 0, 0] };
}
/// The cut-out and its marks, at the current look.
function drawLook() {
  lookView.draw(S.look);
  drawOrientationMarks(marksCtx, marksCanvas.width, marksCanvas.height, lookScene(), S.look);
}
const marksCtx = marksCanvas.getContext("2d");
function drawFrame(vf) {
  if (lookView) {
    lookView.upload(vf);
    drawLook();
    S.lookDirty = false;
    showSurface("look");
    return;
  }
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = "#000";
  if (S.zoom !== 1) ctx.fillRect(0, 0, canvas.width, canvas.height);
  ctx.setTransform(S.zoom, 0, 0, S.zoom, S.panX, S.panY);
  ctx.drawImage(vf, 0, 0, canvas.width, canvas.height);
  ctx.setTransform(1, 0, 0, 1, 0, 0);
}

let lastTick = 0;
function tick(now) {
  requestAnimationFrame(tick);
  if (!S.db) return;
  if (S.pending && lastTick) S.pending.diag.maxTickGap = Math.max(S.pending.diag.maxTickGap, now - lastTick);
  lastTick = now;
  render(now);
  // A switch drawn by an input's handler or just now goes out with this display frame, once this
  // callback (and the pump's work in it) is done: its clock stops here.
  if (S.presenting) {
    onScreen(S.presenting);
    // The HUD written in render() carried the provisional figure (to the draw): show the final one in
    // this same display frame, not one frame later.
    updateHud(currentFrame());
  }
}
/// Stops a switch's clock (issue 30, honest latency): from the input event's own timeStamp to the
/// display frame in which the canvas changed — at the end of that frame's rAF callback, once the drawn
/// pixels exist (a 1-pixel read waits for the GPU, which may still be drawing the cut-out: the draw
/// call only queues it). Not from the key handler and not to the draw call.
function onScreen(w) {
  // The 2-D canvas is not read back: Chromium may move a canvas that is read from to the CPU. Its
  // drawImage is rasterised when this frame is committed, right after this callback.
  const t1 = performance.now();
  if (surface === "look" && lookView) lookView.finish();
  const t = performance.now();
  w.diag.finishMs = t - t1;  // waiting for the GPU's drawing
  w.diag.untilFinishMs = t1 - w.t0;  // draw, pump and the rest of the callback
  w.ms = t - w.t0;
  w.screenAt = t;
  if (S.presenting === w) S.presenting = null;
}
/// Draws what changed (a new frame, a switch's stream, a new look) and runs the pump. Called every
/// display frame and, when an input changed the picture and its frame is decoded, at once from the
/// input's handler: the change then reaches the next display frame instead of waiting a frame for
/// the next rAF callback to draw it.
// A frame the database marks damaged: its placeholder, never its decoded pixels.
function drawDamaged(st, frame) {
  drawPlaceholder(S.camera, S.task, "damaged", `${st.url}: frame ${frame} fails its frame checks (checksum, movie identity or position)`);
}
function render(now) {
  // Until the first frame is on the screen the clock stands at the start frame: fetching the index and
  // decoding the first frame is not time played (the desktop window: Engine::restart_clock()).
  if (S.firstFrameMs === null && S.playing) S.anchorTime = performance.now();
  const frame = currentFrame();
  const st = stream(S.camera, S.task);
  const key = `${S.camera}/${S.task}/${frame}`;
  const same = S.shown && S.shown.camera === S.camera && S.shown.task === S.task && S.shown.frame === frame;
  let drawn = false, status = "ok", shownFrame = frame;
  // A switch counts as a hit when the first display frame after the key shows the new stream.
  const firstTickAfterSwitch = S.pending !== null && !S.pending.seen;
  if (S.pending && !S.pending.seen) {
    const d = S.pending.diag, t = performance.now();
    d.frameTimeMs = now - S.pending.t0;  // the display frame's begin time, after the key
    d.firstTickMs = t - S.pending.t0;  // when its rAF callback ran
    d.demuxMs = traffic.demuxMs - S.pending.demux0;
    d.outputMs = traffic.outputMs - S.pending.output0;
    d.warmMs = traffic.warmMs - S.pending.warm0;  // decoders created and configured meanwhile
    d.warms = traffic.warms - S.pending.warms0;
  }
  if (S.pending) S.pending.seen = true;
  if (same && S.lookDirty && lookView && lookView.hasFrame && surface === "look") {
    drawLook();  // the look changed (drag, wheel, walk) or the cameras came in, the frame did not
    S.lookDirty = false;
    drawMinimap();
  }
  if (!same) {
    const vf = cache.get(key);
    if (st.status === "ok" && st.damaged && st.damaged.has(frame)) {
      status = "damaged";
      drawDamaged(st, frame);
      drawn = true;
    } else if (vf) {
      drawFrame(vf);
      drawn = true;
      S.message = "";
    } else if (st.status === "missing" || st.status === "unreadable") {
      status = st.status;
      drawPlaceholder(S.camera, S.task, status, st.message);
      drawn = true;
    } else if (st.status === "ok" && st.fragmentOf(frame) < 0) {
      status = "unreadable";
      drawPlaceholder(S.camera, S.task, status, `${st.url}: truncated before frame ${frame}`);
      drawn = true;
    } else {
      // The engine waits for the frame it needs; here the clock runs on meanwhile, so when a frame of
      // this stream decoded on demand arrives late, show it rather than keep the old stream on screen.
      if (S.playing) {
        const sameStream = S.shown && S.shown.camera === S.camera && S.shown.task === S.task;
        const late = lateFrame({
          frame, dir: S.dir, frames: S.db.frames, shownFrame: sameStream ? S.shown.frame : null,
          isDecoded: (g) => cache.has(`${S.camera}/${S.task}/${g}`),
          isDamaged: (g) => st.status === "ok" && !!st.damaged && st.damaged.has(g),
        });
        if (late && late.damaged) {
          status = "damaged";
          drawDamaged(st, late.frame);
        } else if (late) {
          drawFrame(cache.get(`${S.camera}/${S.task}/${late.frame}`));
        }
        if (late) {
          drawn = true;
          shownFrame = late.frame;
        }
      }
    }
  }
  if (drawn) {
    const now = performance.now();
    S.shown = { camera: S.camera, task: S.task, frame: shownFrame, status };
    S.shownKey = `${S.camera}/${S.task}/${shownFrame}`;
    if (S.firstFrameMs === null) { S.firstFrameMs = now; S.firstShown = { ...S.shown }; mark("drawn"); }
    if (S.pending) {
      // ms: until the display frame that shows this draw (set at the next rAF; until then the draw).
      const w = { command: S.pending.command, from: S.pending.from, to: [S.camera, S.task], ms: now - S.pending.t0, drawMs: now - S.pending.t0,
                  t0: S.pending.t0, hit: firstTickAfterSwitch, lag: (S.dir * (frame - shownFrame) + S.db.frames) % S.db.frames, diag: S.pending.diag };
      S.switches.push(w);
      S.pending = null;
      S.presenting = w;  // on screen with the display frame of this or the next rAF callback (tick)
    }
    drawMinimap();
  }
  pump();
  // The decoders a switch left cold, closed one per display frame once the switch is on screen.
  if (S.releaseDue && !S.pending) S.releaseDue = releaseDecoders(1) > 0;
  updateHud(frame);
}

// --- hud ---
function updateHud(frame) {
  const db = S.db;
  const text = hudText(S, frame, options);
  if (text !== lastHud) hud.textContent = lastHud = text;  // a DOM write per display frame costs a layout
  // The legend changes with the task and, for relative windows, with the frame's reference.
  const bars = taskLegend(db, S.task, frame), legendKey = JSON.stringify(bars);
  if (legendKey !== lastLegend) { drawLegend(legendCanvas, bars); lastLegend = legendKey; S.legend = bars; }
  if (statusLine.textContent !== S.message) statusLine.textContent = S.message;
  updateReadout();
}
let lastHud = "", lastLegend = "";

// --- readout ---
const { readoutAt, updateReadout } = installReadoutHover({ S, canvas, cache, isLookView: () => lookView });

// --- minimap ---
function drawMinimap() {
  if (!S.cams) return;
  const nb = COLUMNS.map((d) => graphNeighbour(S.camera, d));
  if (S.latticeMap) {
    const fovH = (2 * Math.atan(Math.tan((S.look.fov * Math.PI) / 360) * (lookCanvas.width / lookCanvas.height)) * 180) / Math.PI;
    S.latticeMap.draw(mapCtx, minimap.width, minimap.height, S.camera, nb.filter((i) => i >= 0), viewDirection(S.cams, S.camera, S.rig.equirect ? S.look : { yaw: 0, pitch: 0, fov: 90 }), S.rig.equirect ? fovH : 0);
    return;
  }
  S.sphereMap ??= new SphereMap(S.cams);
  S.sphereMap.draw(mapCtx, minimap.width, minimap.height, S.camera, nb);
}
minimap.addEventListener("click", (e) => {
  if (!S.cams) return;
  const r = minimap.getBoundingClientRect();
  const px = ((e.clientX - r.left) / r.width) * minimap.width, py = ((e.clientY - r.top) / r.height) * minimap.height;
  inputEventTime = e.timeStamp;
  const c = S.latticeMap ? S.latticeMap.pick(px, py, minimap.width, minimap.height, S.camera)
                         : (S.sphereMap ??= new SphereMap(S.cams)).pick(px, py, minimap.width, minimap.height);
  if (c >= 0 && c !== S.camera) { trail.clear(); select(c, S.task, "minimap"); }
});

// --- input ---
function zoomAt(factor, px, py) {
  const z = Math.max(1, Math.min(16, S.zoom * factor));
  const f = z / S.zoom;
  S.panX = px - (px - S.panX) * f;
  S.panY = py - (py - S.panY) * f;
  S.zoom = z;
  if (z === 1) { S.panX = 0; S.panY = 0; }
  S.shown = null;  // redraw
}
// Arrow keys (and Z/X): the opposite of the last move(s) retraces them (MoveTrail in cameras.js).
// A refused move is explained by the key handler (keys.json's refusal), not here.
const move = (d) => select(trail.next(S.camera, d, graphNeighbour(S.camera, d)), S.task, d);
/// Walks to the neighbour in the walk's direction relative to the view, keeping the world view
/// direction (player::walk_keeping_view).
function walk(w) {
  const to = walkTarget(S.cams, S.camera, S.look, w, S.keys && S.keys.walk ? S.keys.walk.min_cos : undefined);
  if (to < 0) return false;
  S.look = lookAfterWalk(S.cams, S.camera, to, S.look);
  S.lookDirty = true;
  trail.clear();
  return select(to, S.task, `walk_${w}`);
}
function setLook(l) {
  S.look = clamped(l);
  S.lookDirty = true;
}
/// Double-click in a walkable 360° database: one step toward the clicked point of the cut-out (Shift:
/// away from it), keeping the world view direction — the desktop's step_toward_click.
function stepTowardClick(x, y, w, h, back) {
  const from = S.camera, cam = basisOfCamera(S.cams, from);
  const d = cutoutDirection(cam, S.look, x, y, w, h);
  const to = neighbourToward(S.cams, from, back ? d.map((v) => -v) : d);
  if (to < 0) { notify(back ? "no camera behind that way" : "no camera that way"); return false; }
  S.look = lookAfterWalk(S.cams, from, to, S.look);
  S.lookDirty = true;
  trail.clear();
  return select(to, S.task, back ? "step_back" : "step_toward");
}
let faceCanvas = null;
/// C: turns the 360° view toward the strongest signal of the frame on screen (the desktop's
/// face_the_action), read from the decoded frame drawn into a canvas of at most 512 columns. False
/// when refused: the key handler says why (keys.json's refusal for the mode, the window's words).
function faceTheAction() {
  const vf = S.shownKey && cache.map.get(S.shownKey);
  if (!S.rig.equirect || !vf || !S.cams) return false;
  const fw = vf.displayWidth ?? vf.width, fh = vf.displayHeight ?? vf.height;
  const W = Math.min(512, fw), H = Math.max(2, Math.round((fh * W) / fw));
  faceCanvas = faceCanvas ?? document.createElement("canvas");
  faceCanvas.width = W;
  faceCanvas.height = H;
  const g = faceCanvas.getContext("2d", { willReadFrequently: true });
  g.drawImage(vf, 0, 0, W, H);
  const px = g.getImageData(0, 0, W, H).data, luma = new Uint8Array(W * H);
  // Video-range luma (16..235), as the desktop reads the decoded frame's Y plane: the rule's "16 levels
  // above the median" means the same there and here.
  for (let i = 0; i < W * H; i++) luma[i] = Math.round(16 + (219 / 255) * (0.299 * px[4 * i] + 0.587 * px[4 * i + 1] + 0.114 * px[4 * i + 2]));
  const cam = basisOfCamera(S.cams, S.camera);
  const d = strongestSignalDirection(luma, W, H, cam);
  if (!d) return false;
  setLook(lookTowards(cam, d, S.look.fov));
  notify(`facing the strongest signal: ${lookText(S.look)}`);
  return true;
}
let notifyTimer = 0;
/// A line in the status bar for 3 s (a key that changed nothing says why).
function notify(text) {
  S.message = text;
  clearTimeout(notifyTimer);
  notifyTimer = setTimeout(() => { if (S.message === text) S.message = ""; }, 3000);
}
function download(url, name) {
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  a.click();
}
const pb = (k, dflt) => (S.keys && S.keys.playback && S.keys.playback[k]) || dflt;
const lk = (k, dflt) => (S.keys && S.keys.look && S.keys.look[k]) || dflt;
/// The engine's and the dispatch's operations (engine_ops.js); OPS below holds only what a page does
/// itself. Each returns false when refused.
const ENGINE = engineOps({ S, clock: { currentFrame, setFrame, setPlaying }, select, move, walk, setLook, notify }).ops;
const OPS = {
  zoom_in: () => zoomAt(1.25, canvas.width / 2, canvas.height / 2),
  zoom_out: () => zoomAt(0.8, canvas.width / 2, canvas.height / 2),
  zoom_reset: () => { S.zoom = 1; S.panX = S.panY = 0; S.shown = null; },
  fullscreen: () => (document.fullscreenElement ? document.exitFullscreen() : document.getElementById("stage").requestFullscreen()).catch((e) => notify(`full screen: ${e.message}`)),
  screenshot: () => download((surface === "look" ? lookCanvas : canvas).toDataURL("image/png"), `panoptes-c${S.camera}-t${S.task}-f${currentFrame()}.png`),
  help: () => { document.getElementById("help").classList.toggle("hidden"); },
  face_action: () => faceTheAction(),
  toggle_hud: () => { S.hudHidden = !S.hudHidden; for (const id of ["hud", "minimap", "legend"]) document.getElementById(id).classList.toggle("off", S.hudHidden); },
};
/// Actions of the desktop that a browser page cannot do (left out of the help).
const NOT_HERE = new Set(["record", "quit"]);
const WHY_NOT = { record: "recording is the desktop player's (panoptes play, R); here use S for a screenshot", quit: "close the tab to quit" };
document.addEventListener("keydown", (e) => {
  if (!S.db) return;
  const b = bindingOf(e, S.keys);
  if (!b) return;
  e.preventDefault();
  if (e.repeat && b.repeat === false) return;  // a held toggle acts once (the table's repeat)
  inputEventTime = e.timeStamp;
  const op = operationOf(S.keys, b.action, S.mode);
  const run = op === null ? null : isFrontEndOperation(b, op) ? OPS[op] : ENGINE[op];
  S.refusal = "";
  if (op !== null && !run) notify(WHY_NOT[op] ?? `${b.desktop}: "${op}" is not available in the web player`);
  else if (!run || run(e) === false) {
    // Refused: the words of keys.json (player::refusal), the same the window shows.
    S.refusal = refusalOf(S.keys, b, S.mode);
    if (S.refusal) notify(S.refusal);
  }
  inputEventTime = 0;
  drawNowIfReady();
});
/// After an input: draw at once when the new picture's frame is decoded (else the rAF draws it when it is).
function drawNowIfReady() {
  if (!S.db || !options.drawOnInput) return;
  if (S.pending ? cache.has(`${S.camera}/${S.task}/${currentFrame()}`) : S.lookDirty) render(performance.now());
}
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const r = canvas.getBoundingClientRect();
  zoomAt(e.deltaY < 0 ? 1.15 : 1 / 1.15, ((e.clientX - r.left) / r.width) * canvas.width, ((e.clientY - r.top) / r.height) * canvas.height);
}, { passive: false });
// 360°: the wheel narrows / widens the field of view (×1.15 a notch, as the desktop).
lookCanvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const k = lk("wheel_fov_factor", 1.15);
  setLook({ ...S.look, fov: S.look.fov * (e.deltaY < 0 ? 1 / k : k) });
}, { passive: false });

let dragLast = null;
const dirs = () => S._dirs ?? (S._dirs = cameraDirections(S.cams));
function cameraVec(col, c) { return [0, 1, 2].map((k) => S.cams[col][3 * c + k]); }
canvas.addEventListener("pointerdown", (e) => {
  if (e.button !== 0 || !S.db || !S.cams) return;
  canvas.setPointerCapture(e.pointerId);
  drag.begin(cameraVec("position", S.camera), cameraVec("up", S.camera), cameraVec("look_at", S.camera));
  dragLast = [e.clientX, e.clientY];
});
canvas.addEventListener("pointermove", (e) => {
  if (!drag.active || !dragLast) return;
  drag.move(e.clientX - dragLast[0], e.clientY - dragLast[1], canvas.getBoundingClientRect().height);
  dragLast = [e.clientX, e.clientY];
  const c = nearestCamera(dirs(), S.cams.shell, drag.dir, S.cams.shell[S.camera]);
  if (c >= 0 && c !== S.camera) { trail.clear(); inputEventTime = e.timeStamp; select(c, S.task, "drag"); }
});
const endDrag = () => { drag.end(); dragLast = null; };
canvas.addEventListener("pointerup", endDrag);
canvas.addEventListener("pointercancel", endDrag);
// 360°: grab-and-drag looks around — the scene follows the pointer, one displayed pixel = fov / height
// degrees (ui/window_app.cpp).
let lookLast = null;
lookCanvas.addEventListener("pointerdown", (e) => {
  if (e.button !== 0) return;
  lookCanvas.setPointerCapture(e.pointerId);
  lookLast = [e.clientX, e.clientY];
});
lookCanvas.addEventListener("pointermove", (e) => {
  if (!lookLast) return;
  const perPx = S.look.fov / Math.max(1, lookCanvas.getBoundingClientRect().height);
  setLook({ ...S.look, yaw: S.look.yaw - (e.clientX - lookLast[0]) * perPx, pitch: S.look.pitch + (e.clientY - lookLast[1]) * perPx });
  lookLast = [e.clientX, e.clientY];
  drawNowIfReady();
});
lookCanvas.addEventListener("dblclick", (e) => {
  if (!S.db || !S.cams || !S.rig.walkable) return;
  e.preventDefault();
  inputEventTime = e.timeStamp;
  const r = lookCanvas.getBoundingClientRect();
  stepTowardClick(e.clientX - r.left, e.clientY - r.top, r.width, r.height, e.shiftKey);
  inputEventTime = 0;
  drawNowIfReady();
});
const endLook = () => { lookLast = null; };
lookCanvas.addEventListener("pointerup", endLook);
lookCanvas.addEventListener("pointercancel", endLook);

/// The key help for the database at hand, from the key table: a one-line hint under the view and the
/// table H shows over the page (help_overlay.js).
function showHelp() {
  if (!S.keys) return;
  const mouse = S.rig.equirect
    ? [["drag", "look around"], ["wheel", "field of view"]].concat(
        S.rig.walkable ? [["double-click", "step toward that point (Shift: away from it)"]] : [])
    : [["drag", "rotate to the nearest camera"], ["wheel", "magnify"]];
  renderHelp(document.getElementById("help"), document.getElementById("hint"), mouse, helpRows(S.keys, S.mode, NOT_HERE));
}

// --- start ---
/// Loads keys.json (beside index.html). Without it the keys do nothing and the page says why — the
/// player keeps no second copy of the table.
async function loadKeys() {
  const url = base + "api/keys.json";
  try {
    const r = await fetch(url, { cache: "no-store" });
    if (!r.ok) throw new Error(`HTTP ${r.status}`);
    S.keys = parseKeyTable(await r.json(), url);
    if (S.keys.look) Object.assign(LOOK_LIMITS, S.keys.look);
    setMode();
    showHelp();
  } catch (e) {
    S.keysError = `the key table ${url} could not be loaded (${e.message}): keys do nothing; the mouse still works. ` +
      "It is written by panoptes serve / export-web of this version.";
    document.getElementById("hint").textContent = S.keysError;
    notify(S.keysError);
    clearTimeout(notifyTimer);  // stays
  }
}
/// The key table's mode: as published for this database (serve, export-web), else by the same rule
/// from the manifest's rig (docs/web.md: panorama = equirectangular, lattice = also a lattice or path).
function setMode() {
  S.mode = (S.keys && S.keys.mode) || (S.rig.walkable ? "lattice" : S.rig.equirect ? "panorama" : "sphere");
}
/// Lattice and path rigs get the top-view map (larger, square); others the longitude/latitude map.
function setupMinimap() {
  S.lookDirty = true;  // the cut-out's orientation marks need the cameras
  if (!(S.rig.lattice || S.rig.path) || !S.cams) return;
  S.latticeMap = new LatticeMap(S.cams, S.domainBox ?? null);
  minimap.width = minimap.height = 260;
  minimap.classList.add("lattice");
  minimap.title = "top view (north up): click a camera of this depth layer";
}
async function main() {
  mark("scripts");
  if (!("VideoDecoder" in window)) {
    statusLine.textContent = "This browser has no WebCodecs VideoDecoder (Chromium 94+, Firefox 130+, Safari 16.4+).";
    return;
  }
  // index.html starts this fetch before the modules load (one round trip less before the first frame).
  const res = await (window.panoptesDatabase ?? fetch(base + "api/database.json", { cache: "no-store" }));
  if (!res.ok) {
    statusLine.textContent = `cannot load the database: HTTP ${res.status} ${res.status === 401 ? "(open the URL with ?token=...)" : ""}`;
    return;
  }
  const db = await res.json();
  mark("database.json");
  // The key table (generated from the C++ one by serve / export-web) and the manifest's rig (360°,
  // lattice) are fetched while the first stream opens; only drawing waits for them.
  const keysLoaded = loadKeys();
  const manifestLoaded = fetch(base + "db/panoptes.json", { cache: "no-store" })
    .then((r) => (r.ok ? r.json() : null)).catch(() => null);  // without it the player shows frames flat
  document.title = `${db.title || "Panoptes"} — Panoptes web player`;
  document.getElementById("title").textContent =
    `${db.title}: ${db.cameras.count} cameras × ${db.tasks.length} tasks, ${db.frames} frames (${db.status})`;
  S.camera = Math.min(Number(params.get("camera") || 0), db.cameras.count - 1);
  S.task = Math.min(Number(params.get("task") || 0), db.tasks.length - 1);
  S.anchorFrame = Math.min(Number(params.get("frame") || 0), db.frames - 1);
  S.anchorTime = performance.now();
  S.db = db;
  // Playback rate: ?fps=N, else the database's preferred rate (the desktop player's rule), else the movies'.
  S.fps = Number(params.get("fps")) || (db.playback_fps > 0 ? db.playback_fps : db.fps);
  pump();  // the first stream's open starts now, not at the first display frame (up to 16 ms later)
  const manifest = await manifestLoaded;
  S.rig = rigOf(manifest, db.cameras.count);
  await keysLoaded;  // its playback and look parameters are needed below
  setMode();
  showHelp();  // the help for this kind of database
  if (S.rig.equirect) {
    try {
      lookView = new LookView(lookCanvas);
    } catch (e) {
      S.message = e.message;  // shown flat, as before
    }
  }
  const dom = manifest && manifest.domain;
  if (dom && Array.isArray(dom.origin) && Array.isArray(dom.spacing) && Array.isArray(dom.dims))
    S.domainBox = { lo: dom.origin, hi: dom.origin.map((o, a) => o + dom.spacing[a] * Math.max(0, dom.dims[a] - 1)) };
  S.sky = dom && dom.up_axis === "z_down" ? [0, 0, -1] : [0, 0, 1];  // store::Domain::sky()
  canvas.width = db.image.width;
  canvas.height = db.image.height;
  // Frames are shown as large as the window allows (in-situ renders are often small). The 360°
  // cut-out fills the same place (2:1, as the desktop window), at the display's pixel density.
  const fit = () => {
    const s = Math.max(0.1, Math.min((innerWidth - 20) / db.image.width, (innerHeight - 110) / db.image.height));
    const w = Math.floor(db.image.width * s), h = Math.floor(db.image.height * s);
    for (const c of [canvas, lookCanvas, marksCanvas]) {
      c.style.width = `${w}px`;
      c.style.height = `${h}px`;
    }
    if (lookView) {
      // At most 1.5 × the panorama's height: at a 90° field of view that is 3 drawn pixels per source
      // pixel already (more only costs fragment work, which software GL pays per pixel); the browser
      // scales the canvas to its place.
      const k = Math.min(1, (1.5 * db.image.height) / (h * devicePixelRatio));
      lookCanvas.width = Math.round(w * devicePixelRatio * k);
      lookCanvas.height = Math.round(h * devicePixelRatio * k);
      marksCanvas.width = Math.round(w * devicePixelRatio);  // lines at the display's resolution
      marksCanvas.height = Math.round(h * devicePixelRatio);
      S.lookDirty = true;
    }
  };
  fit();
  addEventListener("resize", fit);
  // The desktop's short-run rule (ui/window_app.cpp): without a preferred rate, a run that would flash
  // by in under 4 s at the movies' rate starts slower (×¼..×1), e.g. 24 frames at 30 fps last 3.2 s.
  const short = pb("short_run", { shortest_run_s: 4, speed_min: 0.25 });
  if (Number(params.get("speed")) > 0) S.speed = Math.min(pb("speed_max", 8), Math.max(pb("speed_min", 0.25), Number(params.get("speed"))));
  else if (!Number(params.get("fps")) && !(db.playback_fps > 0) && db.frames > 1)
    S.speed = Math.min(1, Math.max(short.speed_min, db.frames / (S.fps * short.shortest_run_s)));
  S.anchorTime = performance.now();  // the clock starts with the first display loop, at that speed
  if (lookView) {
    // A 360° frame starts looking along the camera's forward direction with a 90° field of view.
    const yaw = Number(params.get("yaw")) || 0, pitch = Number(params.get("pitch")) || 0, fov = Number(params.get("fov")) || lk("fov_deg", 90);
    S.look = clamped({ yaw, pitch, fov });
    showSurface("look");
  }
  requestAnimationFrame(tick);
  // The first frame does not need the cameras: it is fetched meanwhile. Navigation by the graph, the
  // mini-map and drag start when the table is in (at 10^6 cameras it is tens of MB).
  if (db.cameras.table) {
    const url = base + "db/" + db.cameras.table;
    const tStart = performance.now();
    fetch(url, { cache: "no-store" })
      .then((r) => { if (!r.ok) throw new Error(`HTTP ${r.status}`); return r.arrayBuffer(); })
      .then((buf) => {
        const t0 = performance.now();
        const cams = parseCameraTable(buf, url);
        if (cams.count !== db.cameras.count) throw new Error(`${cams.count} cameras, the manifest says ${db.cameras.count}`);
        S.cameraTableMs = { started: tStart, loaded: t0, parsed: performance.now(), bytes: buf.byteLength };
        S.cams = cams;
        S.sphereMap = null;
        setupMinimap();
        drawMinimap();
      })
      .catch((e) => { S.message = `${url}: ${e.message}`; });
  } else {
    S.cams = camerasFromJson(db.cameras, db.graph);
    S.sphereMap = null;
    setupMinimap();
  }
  // A database still being written grows: re-read its manifest every 2 s and re-open the streams
  // (their fragment indexes) when the frame count moved on.
  const refresh = setInterval(async () => {
    if (S.db.status !== "running") return clearInterval(refresh);
    try {
      const next = await (await fetch(base + "api/database.json", { cache: "no-store" })).json();
      S.db.status = next.status;
      if (next.frames !== S.db.frames) {
        S.db.frames = next.frames;
        S.db.times = next.times;
        S.db.fields = next.fields;  // the new frames' references: the legend and the readout scale by them
        for (const s of streams.values()) s.close();
        streams.clear();
        document.getElementById("title").textContent =
          `${next.title}: ${next.cameras.count} cameras × ${next.tasks.length} tasks, ${next.frames} frames (${next.status})`;
      }
    } catch { /* the server may be restarting: try again next time */ }
  }, 2000);
}

installTestApi({ S, streams, cache, options, drag, canvas, ctx, lookCanvas, surface: () => surface, currentFrame, setLook,
                 setPlaying, select, graphNeighbour, dirs, readoutAt });

main().catch((e) => { statusLine.textContent = `error: ${e.message}`; });
