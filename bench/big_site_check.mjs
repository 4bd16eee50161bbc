// The web player on a large exported packed site (issue 46, million_bench): a static server that
// honours byte ranges (as object stores do) serves the export-web site; headless Chromium opens it and
// shows N random streams of a synth-db database (stamped frames): each must appear with status ok and
// its (camera, task, frame) stamp read back from the canvas pixels. Prints a Markdown row: site files,
// open ms, median and worst ms from select() to the stream's frame on screen, requests and bytes per
// stream.
//   node big_site_check.mjs SITE_DIR CHROMIUM NODE_MODULES [N [--no-stamp]]
// (--no-stamp: frames without stamps, e.g. an in-situ database: each stream must show with status ok)
import { createRequire } from "node:module";
import fs from "node:fs";
import path from "node:path";
import { serveStatic } from "../web/test/static_server.mjs";

const [siteDir, chromium, nodeModules, nArg, stampArg] = process.argv.slice(2);
const stamped = stampArg !== "--no-stamp";
const N = Number(nArg || 20);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");

const server = await serveStatic(siteDir, { ranges: true });
const url = server.url + "?play=0";
const count = () => ({ n: server.requests.length, bytes: server.requests.reduce((t, r) => t + (r.bytes || 0), 0) });
const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox", "--disable-dev-shm-usage"] });
let failures = 0;
try {
  const page = await browser.newPage();
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded(), { timeout: 120000 });
  const openMs = Date.now() - t0;
  const db = JSON.parse(fs.readFileSync(path.join(siteDir, "api/database.json"), "utf8"));
  const C = db.cameras.count, T = db.tasks.length;
  let seed = 46;
  const rnd = (n) => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed % n; };
  const ms = [];
  const before = count();
  for (let i = 0; i < N; i++) {
    const c = rnd(C), t = rnd(T);
    const s = Date.now();
    await page.evaluate((c, t) => window.panoptes.select(c, t), c, t);
    await page.waitForFunction((c, t) => { const s = window.panoptes.shown(); return s && s.camera === c && s.task === t && s.status !== "loading"; }, { timeout: 30000 }, c, t);
    ms.push(Date.now() - s);
    const { shown, stamp } = await page.evaluate(() => ({ shown: window.panoptes.shown(), stamp: window.panoptes.readStamp() }));
    if (shown.status !== "ok" || (stamped && (!stamp || stamp.camera !== c || stamp.task !== t || stamp.frame !== shown.frame))) {
      failures++;
      console.error(`stream (${c}, ${t}): shows ${JSON.stringify(shown)}, stamp ${JSON.stringify(stamp)}`);
    }
  }
  ms.sort((a, b) => a - b);
  const files = fs.readdirSync(siteDir, { recursive: true }).filter((f) => fs.statSync(path.join(siteDir, f)).isFile()).length;
  console.log(`| ${C} x ${T} | ${files} | ${openMs} | ${ms[Math.floor(ms.length / 2)]} / ${ms[ms.length - 1]} | ${((count().n - before.n) / N).toFixed(1)} / ${((count().bytes - before.bytes) / N / 1024).toFixed(1)} kB | ${N - failures} of ${N} |`);
} finally {
  await browser.close();
  server.close();
}
process.exit(failures ? 1 : 0);
