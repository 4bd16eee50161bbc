// Slice legends and the value readout in headless Chromium (see legend_test.sh, issue 41). The field
// and camera are the shell script's (and src/player/value_readout_test.cpp's): phi = A sin(2 pi x / 63)
// cos(pi y / 47) on a 64x48x32 grid, a z slice at 15.5 seen from (31.5, 23.5, 95.5), fov 40, 256x192.
//   node legend_test.mjs URL CHROMIUM NODE_MODULES [SCREENSHOT_DIR]
import { createRequire } from "node:module";
import assert from "node:assert/strict";
import path from "node:path";

const [url, chromium, nodeModules, shotDir] = process.argv.slice(2);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");

const NX = 64, NY = 48, SLICE_Z = 15.5, W = 256, H = 192, AMPLITUDE = [3e-5, 6e-5], FRAME = 1;
const field = (x, y) => AMPLITUDE[FRAME] * Math.sin((2 * Math.PI * x) / (NX - 1)) * Math.cos((Math.PI * y) / (NY - 1));
// Camera::ray of pixel (x, y) for the camera above the slice (forward -z, up +y, right = forward x up = +x).
const tanHalf = Math.tan((40 * Math.PI) / 360), eye = [31.5, 23.5, 95.5];
function truth(x, y) {
  const sx = ((2 * (x + 0.5)) / W - 1) * tanHalf * (W / H), sy = (1 - (2 * (y + 0.5)) / H) * tanHalf;
  const t = (SLICE_Z - eye[2]) / -1;  // direction (sx, sy, -1): z falls by 1 per unit of t
  const px = eye[0] + sx * t, py = eye[1] + sy * t;
  const on = px >= 0 && px <= NX - 1 && py >= 0 && py <= NY - 1;
  return { on, value: on ? field(px, py) : 0 };
}
const interior = (x, y) => truth(x - 2, y - 2).on && truth(x + 2, y + 2).on;
const quantile = (v, q) => { const s = [...v].sort((a, b) => a - b); return s.length ? s[Math.round(q * (s.length - 1))] : 0; };

const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox", "--disable-dev-shm-usage"] });
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
const page = await browser.newPage();
await page.setViewport({ width: 900, height: 700 });
const errors = [];
page.on("pageerror", (e) => errors.push(e.message));
await page.goto(`${url}?play=0&frame=${FRAME}`);
await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.shown().status === "ok" &&
  window.panoptes.camerasLoaded(), { timeout: 30000 });

// Frame pixels on a lattice over the picture, read as a hover would (the decoded frame's pixel).
const readings = await page.evaluate((W, H) => {
  const out = [];
  for (let y = 1; y < H; y += 3) for (let x = 1; x < W; x += 3) out.push(window.panoptes.readoutAt(x, y));
  return out;
}, W, H);

await check("legend: a slice's legend has the slice's colours at each value", async () => {
  const { lo, hi } = readings.find((r) => r && r.kind !== "none");
  const samples = readings.filter((r) => r && interior(r.x, r.y) && truth(r.x, r.y).value > lo && truth(r.x, r.y).value < hi);
  // The legend canvas (legend.js drawLegend): first bar 200 CSS px wide at x 10, y 19..31.
  const legend = await page.evaluate(() => {
    const c = document.getElementById("legend"), g = c.getContext("2d"), dpr = c.width / parseFloat(c.style.width);
    const row = Math.round(25 * dpr), px = [];
    for (let i = 0; i <= 196; i++) px.push(Array.from(g.getImageData(Math.round((12 + i) * dpr), row, 1, 1).data.slice(0, 3)));
    return { hidden: c.hidden, px };
  });
  assert.equal(legend.hidden, false, "the legend is shown");
  const diffs = samples.map((r) => {
    // Bar pixel 12 + i covers the value at (2 + i + 0.5) / 200 of the window.
    const i = Math.min(196, Math.max(0, Math.round(((truth(r.x, r.y).value - lo) / (hi - lo)) * 200 - 2.5)));
    return Math.max(...[0, 1, 2].map((k) => Math.abs(r.rgb[k] - legend.px[i][k])));
  });
  const p50 = quantile(diffs, 0.5), p95 = quantile(diffs, 0.95);
  console.log(`     slice pixel vs legend canvas at its true value (levels, max of r, g, b): median ${p50}, p95 ${p95}, max ${quantile(diffs, 1)} over ${diffs.length} pixels`);
  assert.ok(diffs.length > 1000, `${diffs.length} samples`);
  assert.ok(p50 <= 4, `median difference ${p50} levels: the legend does not show the slice's colours`);
  assert.ok(p95 <= 10, `p95 difference ${p95} levels`);
});

await check("readout: the value under a pixel of the H.264 slice, within the colour map's resolution", async () => {
  const err = [];
  let offRead = 0, onNone = 0, on = 0;
  for (const r of readings) {
    assert.ok(r, "every pixel of a slice task has a readout");
    const t = truth(r.x, r.y);
    if (!t.on) { offRead += r.kind !== "none"; continue; }
    if (!interior(r.x, r.y)) continue;
    on++;
    if (r.kind === "none") { onNone++; continue; }
    if (r.kind === "value") err.push(Math.abs(r.value - t.value) / r.resolution);
  }
  const p50 = quantile(err, 0.5), p95 = quantile(err, 0.95), max = quantile(err, 1);
  console.log(`     readout error / resolution over ${err.length} interior pixels: median ${p50.toFixed(2)}, p95 ${p95.toFixed(2)}, max ${max.toFixed(2)}; ${onNone} of ${on} interior pixels without a reading; ${offRead} off-slice pixels read`);
  assert.equal(offRead, 0, "a pixel off the slice gave a value");
  assert.ok(onNone <= on / 100, `${onNone} interior pixels without a reading`);
  // The bounds of value_readout_test.cpp (measured there 1.23 / 3.72 / 13.2 on every pixel, here on every 3rd).
  assert.ok(p50 <= 1.5 && p95 <= 4.5 && max <= 16, `error median ${p50}, p95 ${p95}, max ${max} resolution steps`);
});

await check("readout: hovering the slice shows the value beside the pointer", async () => {
  const box = await page.$eval("#view", (c) => { const r = c.getBoundingClientRect(); return { x: r.left, y: r.top, w: r.width, h: r.height }; });
  const fx = 90, fy = 100;  // a frame pixel inside the slice
  await page.mouse.move(box.x + ((fx + 0.5) / W) * box.w, box.y + ((fy + 0.5) / H) * box.h);
  await page.waitForFunction(() => window.panoptes.readout() !== null, { timeout: 5000 });
  const { readout, text, hidden } = await page.evaluate(() => ({ readout: window.panoptes.readout(), text: document.getElementById("readout").textContent,
                                                                   hidden: document.getElementById("readout").hidden }));
  assert.equal(hidden, false);
  assert.equal(text, readout.text);
  assert.equal(readout.kind, "value", text);
  assert.ok(Math.abs(readout.value - truth(readout.x, readout.y).value) <= 4 * readout.resolution, `${text} vs ${truth(readout.x, readout.y).value}`);
  assert.match(text, /^phi = -?[0-9.e+-]+ +\(\+-[0-9.e+-]+\)$|^\S+ = /);
  if (shotDir) await page.screenshot({ path: path.join(shotDir, "web_readout.png") });
  await page.mouse.move(box.x + 3, box.y + 3);  // the background: no reading
  await page.waitForFunction(() => window.panoptes.readout() && window.panoptes.readout().kind === "none", { timeout: 5000 });
});

await check("no page errors", async () => assert.deepEqual(errors, []));
await browser.close();
if (failures) { console.log(`${failures} check(s) failed`); process.exit(1); }
