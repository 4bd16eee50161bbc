// Drives the web player in headless Chromium (see browser_test.sh). Every check reads the frame
// stamp back from the canvas pixels, so it fails when the player shows the wrong (camera, task, frame).
import { createRequire } from "node:module";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { serveStatic } from "./static_server.mjs";

const [serveArg, siteDir, chromium, nodeModules, liveUrl, liveDir] = process.argv.slice(2);
const serveBase = serveArg.replace(/\?.*/, "");  // the URL printed by serve, without ?token=
const serveUrl = serveArg;
const require = createRequire(nodeModules + "/");
// Until serve / export-web publish api/keys.json (issue 30), the page gets the table built from the C++ source.
const puppeteer = require("puppeteer-core");

// The exported site behind the plainest static server: whole files only (200, no Range support).
const staticServer = await serveStatic(siteDir, { ranges: false });
const staticUrl = staticServer.url;

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--disable-dev-shm-usage", "--autoplay-policy=no-user-gesture-required"],
});
let failures = 0;
async function check(name, fn) {
  const t0 = Date.now();
  try {
    await fn();
    console.log(`ok   ${name} (${Date.now() - t0} ms)`);
  } catch (e) {
    failures++;
    console.log(`FAIL ${name}: ${e.message.split("\n").slice(0, 12).join(" | ")}`);
  }
}

async function open(url) {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  // Fetches of the missing and corrupt movies' indexes fail by design (404/422): not an error here.
  page.on("console", (m) => m.type() === "error" && !/status of 40[4]|status of 422/.test(m.text()) && errors.push(m.text()));
  await page.goto(url);
  await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded(), { timeout: 20000 });
  return { page, errors };
}

/// Waits until the canvas shows (camera, task, frame) and its pixels carry that stamp.
async function expectShown(page, camera, task, frame, what) {
  try {
    await page.waitForFunction(
      (c, t, f) => {
        const s = window.panoptes.shown();
        return s && s.camera === c && s.task === t && (f === null || s.frame === f);
      },
      { timeout: 10000 }, camera, task, frame);
  } catch {
    const s = await page.evaluate(() => window.panoptes.shown());
    throw new Error(`${what}: expected (${camera}, ${task}, ${frame}) on screen, shows ${JSON.stringify(s)}`);
  }
  const { shown, stamp } = await page.evaluate(() => ({ shown: window.panoptes.shown(), stamp: window.panoptes.readStamp() }));
  assert.deepEqual(stamp, { camera: shown.camera, task: shown.task, frame: shown.frame }, `${what}: stamp in the canvas pixels`);
  return shown;
}

const db = await (await fetch(serveBase + "api/database.json", { headers: { Authorization: "Bearer t0k3n" } })).json();
const [L, R, U, D] = [0, 1, 2, 3];
// The cameras come from the database's binary camera table (served as it is), read with the player's
// parser, checked here against the server's inline JSON form of the same cameras.
const { parseCameraTable } = await import(path.join(siteDir, "cameras.js"));
assert.ok(db.cameras.table, "database.json names the camera table");
assert.equal(db.graph, undefined, "no per-camera rows in database.json for a database with a camera table");
db.cameras = parseCameraTable(await (await fetch(serveBase + "db/" + db.cameras.table, { headers: { Authorization: "Bearer t0k3n" } })).arrayBuffer());
const graph = Array.from({ length: db.cameras.count }, (_, i) => Array.from(db.cameras.neighbours.subarray(6 * i, 6 * i + 6)));
{
  const inline = await (await fetch(serveBase + "api/database.json?cameras=inline", { headers: { Authorization: "Bearer t0k3n" } })).json();
  assert.deepEqual(graph, inline.graph, "camera table graph = inline graph");
  for (const col of ["lat_deg", "lon_deg", "shell", "position", "look_at", "up"])
    assert.deepEqual(Array.from(db.cameras[col]), inline.cameras[col], `camera table column ${col}`);
}

await check("keys: every command shows the expected stamp", async () => {
  const { page, errors } = await open(serveUrl + "&play=0");
  await expectShown(page, 0, 0, 0, "start");
  let c = 0;
  for (const [key, col] of [["ArrowRight", R], ["ArrowRight", R], ["ArrowLeft", L], ["ArrowUp", U], ["ArrowDown", D]]) {
    if (graph[c][col] < 0) continue;
    c = graph[c][col];
    await page.keyboard.press(key);
    await expectShown(page, c, 0, 0, key);
  }
  await page.keyboard.press("Tab");
  await expectShown(page, c, 1, 0, "Tab");
  await page.keyboard.down("Shift");
  await page.keyboard.press("Tab");
  await page.keyboard.up("Shift");
  await expectShown(page, c, 0, 0, "Shift+Tab");
  await page.keyboard.press("PageUp");  // isovalue axis +1 = task 1
  await expectShown(page, c, 1, 0, "PageUp");
  await page.keyboard.press("PageUp");
  await expectShown(page, c, 2, 0, "PageUp");
  await page.keyboard.press("PageDown");
  await expectShown(page, c, 1, 0, "PageDown");
  for (let f = 1; f <= 5; f++) {  // through a fragment boundary (gop 4): delta frames decode too
    await page.keyboard.press(".");
    await expectShown(page, c, 1, f, ". step");
  }
  await page.keyboard.press(",");
  await expectShown(page, c, 1, 4, ", step");
  await page.keyboard.press("End");
  await expectShown(page, c, 1, db.frames - 1, "End");
  await page.keyboard.press("Home");
  await expectShown(page, c, 1, 0, "Home");
  assert.deepEqual(errors, []);
  await page.close();
});

await check("keys: the opposite arrow retraces the last moves; HUD numbers tasks from 1; legend", async () => {
  // The rule itself on a graph whose Down is not mutual (several cameras below share the one above),
  // as around a sky pole: cameras.js's MoveTrail, which the player's arrow keys use.
  const { MoveTrail } = await import(path.join(siteDir, "cameras.js"));
  const g = { 0: { up: 3 }, 1: { up: 3 }, 3: { up: 4, down: 2 }, 4: { down: 1 } };
  const t = new MoveTrail();
  const press = (c, d) => t.next(c, d, g[c]?.[d] ?? -1);
  let c = 1;
  for (const d of ["up", "up", "down", "down"]) c = press(c, d);
  assert.equal(c, 1, "Up, Up, Down, Down returns to 1 (the graph alone: 1 -> 3 -> 4 -> 1 -> -1)");
  assert.equal(press(3, "down"), 2, "after a jump elsewhere, Down follows the graph");
  // In the player: Right, Right, Left, Left back at the start; key 2 reads "task 2/3" in the HUD.
  const { page, errors } = await open(serveUrl + "&play=0");
  await expectShown(page, 0, 0, 0, "start");
  const walked = [0];
  for (const key of ["ArrowRight", "ArrowRight"]) {
    const next = graph[walked[walked.length - 1]][R];
    if (next < 0) break;
    walked.push(next);
    await page.keyboard.press(key);
    await expectShown(page, next, 0, 0, key);
  }
  for (let k = walked.length - 2; k >= 0; k--) {
    await page.keyboard.press("ArrowLeft");
    await expectShown(page, walked[k], 0, 0, "ArrowLeft retraces");
  }
  await page.keyboard.press("2");
  await expectShown(page, 0, 1, 0, "key 2 = task 2");
  const hudText = await page.evaluate(() => document.getElementById("hud").textContent);
  assert.match(hudText, new RegExp(`task 2 of ${db.tasks.length}: `), "the HUD numbers tasks as the digit keys do");
  assert.match(hudText, new RegExp(`frame 0 of ${db.frames} `), "the HUD numbers frames from 0, as the desktop");
  // A synthetic database records no windows: no legend.
  assert.equal(await page.evaluate(() => document.getElementById("legend").hidden), true, "no legend without windows");
  assert.deepEqual(errors, []);
  await page.close();
});

// Issue 44: the key help was one run-on paragraph under the view, cut off at 1280x720 and 1600x1000.
// H opens a table over the page: every row of the key table inside the window or reachable by scrolling
// the overlay itself, and H closes it.
await check("help: H shows every key in an overlay that fits 1280x720 and 1600x1000", async () => {
  for (const [width, height] of [[1280, 720], [1600, 1000]]) {
    const { page, errors } = await open(serveUrl + "&play=0");
    await page.setViewport({ width, height });
    assert.equal(await page.evaluate(() => document.getElementById("help").classList.contains("hidden")), true, "closed at first");
    await page.keyboard.press("h");
    const m = await page.evaluate(() => {
      const el = document.getElementById("help"), r = el.getBoundingClientRect();
      const rows = [...el.querySelectorAll(".row")];
      const last = rows[rows.length - 1].getBoundingClientRect();
      return { shown: !el.classList.contains("hidden"), left: r.left, top: r.top, right: r.right, bottom: r.bottom,
               rows: rows.length, scroll: el.scrollHeight, client: el.clientHeight, overflow: getComputedStyle(el).overflowY,
               lastInside: last.right <= r.right + 1 && (last.bottom <= r.bottom + 1 || el.scrollHeight > el.clientHeight),
               hint: document.getElementById("hint").textContent };
    });
    assert.ok(m.shown, "H opens the help");
    assert.ok(m.left >= 0 && m.top >= 0 && m.right <= width && m.bottom <= height, `${width}x${height}: the overlay is inside the window (${JSON.stringify(m)})`);
    assert.ok(m.rows >= 20, `${m.rows} rows`);
    assert.ok(m.scroll <= m.client || m.overflow === "auto", "rows beyond the window scroll inside the overlay");
    assert.ok(m.lastInside, "the last row is inside the overlay or reachable by its scroll");
    assert.match(m.hint, /^H: keys and mouse/);
    await page.screenshot({ path: `${process.env.SHOT_DIR || "/tmp"}/web-help-${width}x${height}.png` });
    await page.keyboard.press("h");
    assert.equal(await page.evaluate(() => document.getElementById("help").classList.contains("hidden")), true, "H closes it");
    assert.deepEqual(errors, []);
    await page.close();
  }
});

await check("playback: frames advance and switches during playback show the right stamp", async () => {
  const { page } = await open(serveUrl + "&play=1");
  await expectShown(page, 0, 0, null, "start");
  const f0 = (await page.evaluate(() => window.panoptes.shown())).frame;
  await page.waitForFunction((f) => window.panoptes.shown().frame !== f, { timeout: 5000 }, f0);
  let c = 0;
  for (let i = 0; i < 3; i++) {  // 0 → 1 → 2 → 3 (camera 4's movie is the corrupt one)
    c = graph[c][R];
    await page.keyboard.press("ArrowRight");
    await expectShown(page, c, 0, null, "ArrowRight while playing");
    await new Promise((r) => setTimeout(r, 150));
  }
  await page.keyboard.press("Tab");
  await expectShown(page, c, 1, null, "Tab while playing");
  const switches = await page.evaluate(() => window.panoptes.switches());
  assert.equal(switches.length, 4);
  await page.keyboard.press(" ");  // pause: the frame stays
  const paused = (await page.evaluate(() => window.panoptes.state())).frame;
  await new Promise((r) => setTimeout(r, 300));
  assert.equal((await page.evaluate(() => window.panoptes.state())).frame, paused, "Space pauses");
  await page.close();
});

await check("playing starts at frame 0 behind a slow network (fetching and decoding are not time played)", async () => {
  const page = await browser.newPage();
  const cdp = await page.target().createCDPSession();
  // 300 ms per request: the first frame arrives ~1 s after the clock used to start (9 frames at 30 fps).
  await cdp.send("Network.emulateNetworkConditions", { offline: false, latency: 300, downloadThroughput: -1, uploadThroughput: -1 });
  await page.goto(serveUrl + "&play=1");
  await page.waitForFunction(() => window.panoptes && window.panoptes.firstShown && window.panoptes.firstShown(), { timeout: 30000 });
  const first = await page.evaluate(() => window.panoptes.firstShown());
  assert.equal(first.frame, 0, `the first frame drawn while playing: ${JSON.stringify(first)}`);
  await page.waitForFunction(() => window.panoptes.shown().frame > 0, { timeout: 10000 });  // and it plays on
  await page.close();
});

await check("drag snaps to the camera nearest the dragged direction", async () => {
  const { page } = await open(serveUrl + "&play=0");
  await expectShown(page, 0, 0, 0, "start");
  const box = await (await page.$("#view")).boundingBox();
  const dx = box.height / 4;  // 45 degrees of orbit
  // Expected (independent of the page's code): rotate the camera's direction about its up vector by
  // -dx * 180 / height degrees, then the camera with the largest dot product.
  const at = (col, i) => [0, 1, 2].map((k) => db.cameras[col][3 * i + k]);
  const norm = (v) => { const n = Math.hypot(...v); return v.map((x) => x / n); };
  const d = norm(at("position", 0).map((x, k) => x - at("look_at", 0)[k]));
  let up = at("up", 0);
  const du = d.reduce((s, x, k) => s + x * up[k], 0);
  up = norm(up.map((x, k) => x - du * d[k]));
  const a = (-dx * Math.PI) / box.height;
  const cr = [up[1] * d[2] - up[2] * d[1], up[2] * d[0] - up[0] * d[2], up[0] * d[1] - up[1] * d[0]];
  const ud = up.reduce((s, x, k) => s + x * d[k], 0);
  const nd = d.map((x, k) => x * Math.cos(a) + cr[k] * Math.sin(a) + up[k] * ud * (1 - Math.cos(a)));
  let best = -1, bestDot = -2;
  for (let i = 0; i < db.cameras.count; i++) {
    const v = norm(at("position", i).map((x, k) => x - at("look_at", i)[k]));
    const dot = v.reduce((s, x, k) => s + x * nd[k], 0);
    if (dot > bestDot) { bestDot = dot; best = i; }
  }
  assert.notEqual(best, 0, "the test drag must reach another camera");
  const y = box.y + box.height / 2, x0 = box.x + box.width / 2 - dx / 2;
  await page.mouse.move(x0, y);
  await page.mouse.down();
  await page.mouse.move(x0 + dx, y, { steps: 12 });
  await page.mouse.up();
  await expectShown(page, best, 0, 0, "drag");
  await page.close();
});

await check("mini-map click, wheel zoom", async () => {
  const { page } = await open(serveUrl + "&play=0");
  await expectShown(page, 0, 0, 0, "start");
  const target = 3;
  const box = await (await page.$("#minimap")).boundingBox();
  const x = box.x + ((db.cameras.lon_deg[target] + 180) / 360) * box.width;
  const y = box.y + ((90 - db.cameras.lat_deg[target]) / 180) * box.height;
  await page.mouse.click(x, y);
  await expectShown(page, target, 0, 0, "mini-map click");
  const view = await (await page.$("#view")).boundingBox();
  await page.mouse.move(view.x + view.width / 2, view.y + view.height / 2);
  await page.mouse.wheel({ deltaY: -200 });
  await page.waitForFunction(() => window.panoptes.state().zoom > 1, { timeout: 3000 });
  await page.keyboard.press("0");
  await page.waitForFunction(() => window.panoptes.state().zoom === 1, { timeout: 3000 });
  await page.keyboard.press(".");
  await expectShown(page, target, 0, 1, "after zoom reset");
  await page.close();
});

await check("missing and corrupt movies show a placeholder and playback goes on", async () => {
  const { page } = await open(serveUrl + "&play=0&camera=5&task=0");
  await expectShown(page, 5, 0, 0, "start");
  await page.keyboard.press("Tab");  // (5, 1) is missing
  await page.waitForFunction(() => window.panoptes.shown().task === 1, { timeout: 10000 });
  let s = await page.evaluate(() => ({ shown: window.panoptes.shown(), stamp: window.panoptes.readStamp(), msg: document.getElementById("status").textContent }));
  assert.equal(s.shown.status, "missing");
  assert.equal(s.stamp, null);
  assert.match(s.msg, /c5\/t1\.mp4/);
  await page.keyboard.press(" ");  // play: the frame moves on under the placeholder
  await page.waitForFunction(() => window.panoptes.shown().frame >= 3, { timeout: 5000 });
  await page.keyboard.press("Tab");  // (5, 2) plays again
  await expectShown(page, 5, 2, null, "after the missing stream");
  await page.evaluate(() => window.panoptes.select(4, 0));  // corrupt
  await page.waitForFunction(() => window.panoptes.shown().camera === 4, { timeout: 10000 });
  s = await page.evaluate(() => window.panoptes.shown());
  assert.equal(s.status, "unreadable");
  const f = s.frame;
  await page.waitForFunction((f0) => window.panoptes.shown().frame !== f0, { timeout: 5000 }, f);
  await page.close();
});

await check("without the token nothing is served", async () => {
  const context = await browser.createBrowserContext();
  const page = await context.newPage();
  const res = await page.goto(serveBase);
  assert.equal(res.status(), 401);
  await context.close();
});

await check("export-web on a static server (no byte ranges) plays the same stamps", async () => {
  const { page } = await open(staticUrl + "?play=0");
  await expectShown(page, 0, 0, 0, "start");
  await page.keyboard.press("ArrowRight");
  await expectShown(page, graph[0][R], 0, 0, "ArrowRight");
  await page.keyboard.press("Tab");
  await expectShown(page, graph[0][R], 1, 0, "Tab");
  await page.close();
});

await check("live database: new frames of a running simulation play without a reload", async () => {
  // browser_test.sh holds the writer lock, so serve reports the database as running; a checkpoint is
  // simulated by rewriting panoptes.json (atomically, as the writer does) with more frames written.
  const manifestPath = path.join(liveDir, "panoptes.json");
  // Each checkpoint also records the frames' references and the task gets a relative window, so the
  // legend must follow them (issue 41.3: the desktop's froze on frame 0's; this player kept the
  // references of the first database.json).
  const reference = (f) => 1e-6 * 2 ** (f / 2);
  const checkpoint = (frames) => {
    const m = JSON.parse(fs.readFileSync(manifestPath, "utf8"));
    m.status = "running";
    m.frames_written = frames;
    m.fields = [{ name: "v", units: "m/s", references: Array.from({ length: frames }, (_, f) => reference(f)) }];
    m.tasks[0].fields = ["v"];
    m.tasks[0].parameters = { window: [0, 1], relative: true };
    fs.writeFileSync(manifestPath + ".tmp", JSON.stringify(m));
    fs.renameSync(manifestPath + ".tmp", manifestPath);
  };
  checkpoint(8);
  const { page, errors } = await open(liveUrl + "?play=1&nbdecode=switch");
  assert.equal(await page.evaluate(() => window.panoptes.state().frames), 8);
  await expectShown(page, 0, 0, null, "live, 8 frames");
  // Keyframes only, nbdecode=switch: the playing neighbour (camera 1) gets its samples
  // fetched and its decoder configured, but no frame decoded until a switch comes to it.
  await page.waitForFunction(() => { const i = window.panoptes.streamInfo(1, 0); return i && i.samples >= 2 && i.decoder === "configured"; }, { timeout: 5000 });
  await new Promise((r) => setTimeout(r, 300));  // ~9 frames of playback: a decode ahead would show
  assert.deepEqual(await page.evaluate(() => window.panoptes.cachedFrames(1, 0)), [], "neighbour decoded ahead with nbdecode=switch");
  // nbdecode=ahead: the neighbour is decoded at even frames only (nbstride 2).
  await page.evaluate(() => { window.panoptes.options.nbDecode = "ahead"; });
  await page.waitForFunction(() => window.panoptes.cachedFrames(1, 0).length >= 2, { timeout: 5000 });
  const nbFrames = await page.evaluate(() => window.panoptes.cachedFrames(1, 0));
  assert.ok(nbFrames.every((f) => f % 2 === 0), `neighbour decoded at frames ${nbFrames}, expected even ones only`);
  // A switch to it shows its stamp, then it is decoded at every frame.
  await page.evaluate(() => { window.panoptes.options.nbDecode = "switch"; window.panoptes.select(1, 0); });
  await expectShown(page, 1, 0, null, "switch to a neighbour while playing");
  await page.waitForFunction(() => window.panoptes.cachedFrames(1, 0).some((f) => f % 2 === 1), { timeout: 5000 });
  await page.evaluate(() => window.panoptes.select(0, 0));
  checkpoint(16);
  await page.waitForFunction(() => window.panoptes.state().frames === 16, { timeout: 8000 });
  await page.waitForFunction(() => window.panoptes.shown().frame >= 8, { timeout: 5000 });
  // Frame 8 on is there for sure only now: its stamp must be in the pixels. Paused at the last frame
  // (the frame shown at the moment of a pause may be a late one, then replaced by the playhead's).
  await page.evaluate(() => window.panoptes.pause());
  await page.keyboard.press("End");
  await expectShown(page, 0, 0, 15, "the last frame of the new checkpoint");
  await page.waitForFunction(() => window.panoptes.legend().length === 1, { timeout: 5000 });
  const bar = (await page.evaluate(() => window.panoptes.legend()))[0];
  assert.equal(bar.hi, reference(15), `legend at frame 15: 0 .. ${bar.hi} m/s, the frame's reference is ${reference(15)}`);
  assert.deepEqual(errors, []);
  await page.close();
});

await check("fragments read by fragmentSamples equal mp4box.js's samples (gop 4 and gop 1)", async () => {
  // Node side: the exported site's player modules (movies.js reads location.search at load).
  globalThis.location = { search: "" };
  const { fragmentSamples } = await import(path.join(siteDir, "movies.js"));
  const { createFile, MP4BoxBuffer } = await import(path.join(siteDir, "vendor/mp4box/mp4box.all.mjs"));
  const cases = [[fs.readFileSync(path.join(siteDir, "db/movies/c0/t0.mp4")), JSON.parse(fs.readFileSync(path.join(siteDir, "api/index/0/0.json"), "utf8")), 4],
                 [fs.readFileSync(path.join(liveDir, "movies/c0/t0.mp4")), await (await fetch(liveUrl + "api/index/0/0.json")).json(), 1]];
  for (const [file, index, gop] of cases) {
    const ab = file.buffer.slice(file.byteOffset, file.byteOffset + file.byteLength), f = index.fragments;
    assert.ok(f.length >= 4, `gop ${gop}: ${f.length} fragments`);
    for (const [a, b] of [[0, f.length], [1, 3], [f.length - 1, f.length]]) {
      const bytes = ab.slice(f[a][0], f[b - 1][0] + f[b - 1][1]);
      const mp4 = createFile(), ref = [];
      mp4.onReady = (i) => { mp4.setExtractionOptions(i.videoTracks[0].id, null, { nbSamples: 100000 }); mp4.start(); };
      mp4.onSamples = (_id, _user, s) => ref.push(...s);
      mp4.appendBuffer(MP4BoxBuffer.fromArrayBuffer(ab.slice(0, index.init_size), 0));
      mp4.appendBuffer(MP4BoxBuffer.fromArrayBuffer(bytes, index.init_size));
      mp4.flush();
      const own = fragmentSamples(bytes);
      assert.equal(own.length, ref.length, `gop ${gop}, fragments ${a}..${b - 1}: sample count`);
      own.forEach((x, i) => {
        assert.equal(x.key, ref[i].is_sync, `gop ${gop}, fragments ${a}..${b - 1}, sample ${i}: keyframe flag`);
        assert.ok(Buffer.from(x.data).equals(Buffer.from(ref[i].data)), `gop ${gop}, fragments ${a}..${b - 1}, sample ${i}: bytes`);
      });
      assert.equal(own.filter((x) => x.key).length, b - a, `gop ${gop}: one keyframe per fragment`);
    }
    // A range cut short is refused with the reason, never read past its end.
    assert.throws(() => fragmentSamples(ab.slice(f[0][0], f[0][0] + f[0][1] - 1)), /outside its mdat|past the end/);
  }
});

await browser.close();
staticServer.close();
if (failures) {
  console.log(`${failures} browser check(s) failed`);
  process.exit(1);
}
