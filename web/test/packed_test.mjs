// The web player on a packed database (see packed_test.sh): served by `panoptes serve`, and as an
// export-web site behind a static server that honours byte ranges. Every check reads the frame stamp
// back from the canvas pixels; the static server's log shows how the bytes were fetched.
import { createRequire } from "node:module";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { serveStatic } from "./static_server.mjs";

const [serveUrl, siteDir, chromium, nodeModules] = process.argv.slice(2);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");

// The exported site as object stores and CDNs serve it: whole files or one byte range, every request logged.
const staticServer = await serveStatic(siteDir, { ranges: true });
const { requests } = staticServer, staticUrl = staticServer.url;

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
  // The browser asks each origin for /favicon.ico once; the player has none. Any other 4xx/5xx is an error.
  page.on("console", (m) => m.type() === "error" && !/status of 404/.test(m.text()) && errors.push(m.text()));
  page.on("response", (r) => r.status() >= 400 && !r.url().endsWith("/favicon.ico") && errors.push(`${r.status()} ${r.url()}`));
  await page.goto(url);
  await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded(), { timeout: 20000 });
  return { page, errors };
}

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
  // Frame 2 of stream (1, 0) is the one damaged on purpose: playback may land on it after a switch.
  const damaged = shown.camera === 1 && shown.task === 0 && shown.frame === 2;
  assert.equal(shown.status, damaged ? "damaged" : "ok", `${what}: status of ${JSON.stringify(shown)}`);
  if (!damaged)
    assert.deepEqual(stamp, { camera: shown.camera, task: shown.task, frame: shown.frame }, `${what}: stamp in the canvas pixels`);
  return shown;
}

const db = JSON.parse(fs.readFileSync(path.join(siteDir, "api/database.json"), "utf8"));
assert.equal(db.layout, "packed");
assert.ok(db.stream_index, "the exported database.json describes its stream index");
const R = 1;
const right = (c) => (c + 1) % 6;  // synthetic ring graph: right = next camera

// Steps, switches camera and task, the last frame, and the damaged frame of stream (1, 0).
async function walk(base, what) {
  const { page, errors } = await open(base + (base.includes("?") ? "&" : "?") + "play=0");
  await expectShown(page, 0, 0, 0, `${what}: start`);
  for (let f = 1; f <= 3; f++) {
    await page.keyboard.press(".");
    await expectShown(page, 0, 0, f, `${what}: . step`);
  }
  await page.keyboard.press("ArrowRight");
  await expectShown(page, right(0), 0, 3, `${what}: ArrowRight`);
  await page.keyboard.press("Tab");
  await expectShown(page, right(0), 1, 3, `${what}: Tab`);
  await page.keyboard.press("End");
  await expectShown(page, right(0), 1, db.frames - 1, `${what}: End`);
  await page.keyboard.press("Home");
  await expectShown(page, right(0), 1, 0, `${what}: Home`);
  // Stream (1, 0): frame 2 fails its checks and shows as damaged; its neighbours play.
  await page.evaluate(() => window.panoptes.select(1, 0));
  await expectShown(page, 1, 0, 0, `${what}: select (1, 0)`);
  await page.keyboard.press(".");
  await expectShown(page, 1, 0, 1, `${what}: frame 1 of (1, 0)`);
  await page.keyboard.press(".");
  await page.waitForFunction(() => { const s = window.panoptes.shown(); return s.frame === 2 && s.camera === 1; }, { timeout: 10000 });
  assert.equal((await page.evaluate(() => window.panoptes.shown())).status, "damaged", `${what}: frame 2 of (1, 0)`);
  await page.keyboard.press(".");
  await expectShown(page, 1, 0, 3, `${what}: frame 3 of (1, 0)`);
  assert.deepEqual(errors, []);
  await page.close();
}

async function playAndSwitch(base, what) {
  const { page, errors } = await open(base + (base.includes("?") ? "&" : "?") + "play=1");
  await expectShown(page, 0, 0, null, `${what}: start`);
  const f0 = (await page.evaluate(() => window.panoptes.shown())).frame;
  await page.waitForFunction((f) => window.panoptes.shown().frame !== f, { timeout: 5000 }, f0);
  let c = 0;
  for (let i = 0; i < 3; i++) {
    c = right(c);
    await page.keyboard.press("ArrowRight");
    await expectShown(page, c, 0, null, `${what}: ArrowRight while playing`);
    await new Promise((r) => setTimeout(r, 150));
  }
  await page.keyboard.press("Tab");
  await expectShown(page, c, 1, null, `${what}: Tab while playing`);
  assert.deepEqual(errors, []);
  await page.close();
}

await check("serve: a packed database steps, switches and shows its damaged frame", () => walk(serveUrl, "serve"));
// Playback with switches once, on the static site (the player's code is the same behind serve).

await check("static site of a packed database: steps, switches, damaged frame; only byte ranges of packs and shards", async () => {
  requests.length = 0;
  await walk(staticUrl, "static");
  assert.equal(requests.filter((r) => r.path.startsWith("api/index")).length, 0, "no per-stream JSON requested");
  const shard = requests.filter((r) => r.path === "api/streams/0.bin");
  const packs = requests.filter((r) => r.path.startsWith("db/packs/"));
  assert.ok(shard.length >= 3 && shard.every((r) => r.status === 206), `stream index entries by Range: ${JSON.stringify(shard)}`);
  // One entry per stream opened: each a fixed-size range (the damaged stream's list is one more).
  assert.ok(shard.filter((r) => r.bytes === db.stream_index.entry_bytes).length >= 3, "entries of entry_bytes each");
  assert.ok(packs.length > 0 && packs.every((r) => r.status === 206 && r.path === "db/packs/s0-r0.pack"),
            `packs by Range only: ${JSON.stringify(packs.filter((r) => r.status !== 206))}`);
  // A stream's fragments lie between the other streams' in the pack: never one range over them all.
  const packBytes = fs.statSync(path.join(siteDir, "db/packs/s0-r0.pack")).size;
  assert.ok(packs.every((r) => r.bytes < packBytes / 4), "no request for a large part of the pack");
});

await check("static site of a packed database: plays and switches while playing", () => playAndSwitch(staticUrl, "static"));

await browser.close();
staticServer.close();
if (failures) {
  console.log(`${failures} browser check(s) failed`);
  process.exit(1);
}
