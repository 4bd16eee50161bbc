// The page's test and benchmark API (window.panoptes): what headless Chromium reads through puppeteer
// (web/test/*.mjs, bench/web_bench.mjs). Kept apart from the player (player.js), which hands it the
// state and functions it reads; nothing here changes what the player shows except select/setLook/pause.
import { traffic, marks } from "./movies.js";
import { readStamp, stampBlock, STAMP_COLUMNS, STAMP_ROWS } from "./stamp.js";
import { walkTarget } from "./look.js";

let pixelHashCanvas = null;

/// p: { S, streams, cache, options, drag, canvas, ctx, lookCanvas, surface() (the shown surface:
/// "flat" or "look"), currentFrame, setLook, setPlaying, select, graphNeighbour, dirs }.
export function installTestApi(p) {
  const { S, streams, cache, options, drag, canvas, ctx, lookCanvas, currentFrame, setLook, setPlaying, select, graphNeighbour, dirs } = p;
  window.panoptes = {
    state: () => ({ camera: S.camera, task: S.task, frame: S.db ? currentFrame() : 0, frames: S.db ? S.db.frames : 0, playing: S.playing, zoom: S.zoom,
                    speed: S.speed, fps: S.fps, direction: S.dir, loop: S.loop, look: { ...S.look }, rig: S.rig, surface: p.surface(), hudHidden: S.hudHidden,
                    // The active parameter axis, the shown camera's shell and what the last key's refusal said (issue 43).
                    axis: S.db && S.db.axes.length ? S.axis : -1, shell: S.cams && S.cams.shell ? S.cams.shell[S.camera] : 0, refusal: S.refusal ?? "" }),
    /// The key table as loaded (null before or when keys.json failed) and why it failed.
    keys: () => (S.keys ? S.keys.rows : null),
    /// The key table's mode in use: sphere, panorama or lattice.
    mode: () => S.mode,
    keysError: () => S.keysError ?? null,
    /// Sets the 360° look {yaw, pitch, fov} (clamped as the desktop).
    setLook: (l) => setLook({ ...S.look, ...l }),
    /// The camera a walk ("forward", "back", "left", "right", "up", "down") leads to from here, or -1.
    walkTarget: (w) => walkTarget(S.cams, S.camera, S.look, w),
    message: () => S.message,
    /// The value readout beside the pointer (slice tasks), null when none; readoutAt(x, y) reads frame
    /// pixel (x, y) of the shown frame as a hover there would.
    readout: () => S.readout ?? null,
    /// The legend's bars as last drawn ({label, units, lo, hi, colours, ...}; [] when none).
    legend: () => S.legend ?? [],
    readoutAt: (x, y) => p.readoutAt(x, y),
    pause: () => setPlaying(false),
    shown: () => S.shown,
    switches: () => S.switches,
    traffic: () => ({ ...traffic }),
    firstFrameMs: () => S.firstFrameMs,
    /// The first frame drawn ({camera, task, frame, status}): playing starts at the start frame.
    firstShown: () => S.firstShown,
    /// The steps to the first frame (ms since navigation start): scripts, database.json, index, init, ...
    marks: () => ({ ...marks }),
    /// When the camera table was in and parsed (performance.now() ms) and its size; null before.
    cameraTable: () => S.cameraTableMs ?? null,
    /// Camera c's neighbour in a direction ("left", ...), -1 if none or the cameras are not loaded yet.
    neighbour: (c, direction) => graphNeighbour(c, direction),
    camerasLoaded: () => S.cams !== null,
    options,
    /// A stream's state: status, decoder state, fragments whose compressed samples are in memory.
    streamInfo: (camera, task) => {
      const st = streams.get(`${camera}/${task}`);
      return st ? { status: st.status, decoder: st.decoder ? st.decoder.state : "none", samples: st.samples.size } : null;
    },
    /// The stamp in the canvas pixels (zoom 1 only), or null.
    readStamp: () => {
      const w = canvas.width, h = canvas.height, b = stampBlock(w, h);
      let g = ctx;
      if (p.surface() === "look") {  // the cut-out does not show the stamp: read the decoded frame it shows
        const vf = S.shownKey && cache.map.get(S.shownKey);
        if (!vf) return null;
        const scratch = document.createElement("canvas");
        scratch.width = w;
        scratch.height = h;
        g = scratch.getContext("2d");
        g.drawImage(vf, 0, 0, w, h);
      }
      const img = g.getImageData(0, 0, STAMP_COLUMNS * b, STAMP_ROWS * b);
      return readStamp(img.data, img.width, w, h);
    },
    /// A hash of the shown canvas's pixels (the latency benchmark polls it for the change).
    pixelHash: () => {
      const c = p.surface() === "look" ? lookCanvas : canvas;
      const scratch = pixelHashCanvas ?? (pixelHashCanvas = document.createElement("canvas"));
      scratch.width = 64;
      scratch.height = 32;
      const g = scratch.getContext("2d", { willReadFrequently: true });
      g.drawImage(c, 0, 0, 64, 32);
      const d = g.getImageData(0, 0, 64, 32).data;
      let hsh = 2166136261;
      for (let i = 0; i < d.length; i++) hsh = Math.imul(hsh ^ d[i], 16777619);
      return hsh >>> 0;
    },
    select: (camera, task) => select(camera, task, "api"),
    /// The decoded frames of (camera, task) in the frame cache, ascending.
    cachedFrames: (camera, task) => [...cache.map.keys()].filter((k) => k.startsWith(`${camera}/${task}/`))
      .map((k) => Number(k.split("/")[2])).sort((a, b) => a - b),
    cameraDirections: () => Array.from(dirs()),
    dragDirection: () => drag.dir,
  };
}
