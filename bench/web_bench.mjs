// The web player's switch latency in headless Chromium (see web_bench.sh.in): per run, a fresh page
// plays the database at its frame rate; after 1.5 s of playback, 40 switches (right, right, Tab,
// up, ...; one every 330 ms, i.e. every ~10 frames at 30 fps) are pressed. Latency = key press to
// the rAF callback that drew the new stream's frame (the player's own record). Bytes per switch =
// bytes fetched during the switching phase / switches (includes the playback's own read-ahead).
import { createRequire } from "node:module";
import fs from "node:fs";
import os from "node:os";

const [url, chromium, nodeModules, dbPath, repsArg, bigUrl, bigPid, bigPath] = process.argv.slice(2);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");
const reps = Number(repsArg || 3);
const keys = ["ArrowRight", "ArrowRight", "Tab", "ArrowUp", "ArrowLeft", "Tab", "ArrowDown", "ArrowRight"];

const median = (a) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.floor((s.length - 1) / 2)] : NaN; };
const pct = (a, p) => { const s = [...a].sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.ceil((p / 100) * s.length) - 1)]; };

async function run(browser, prefetch, extra = "") {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 900 });
  // WEB_BENCH_VERBOSE: long animation frames (> 50 ms, with the scripts that ran in them) are matched
  // to the slow switches.
  if (process.env.WEB_BENCH_VERBOSE)
    await page.evaluateOnNewDocument(() => {
      window.__loaf = [];
      try {
        new PerformanceObserver((l) => { for (const e of l.getEntries()) window.__loaf.push({ start: e.startTime, duration: e.duration, blocking: e.blockingDuration, render: e.renderStart, scripts: e.scripts.map((x) => `${x.invoker}:${x.sourceFunctionName}@${(x.sourceURL || "").split("/").pop()} ${x.duration.toFixed(0)}ms`) }); })
          .observe({ type: "long-animation-frame", buffered: true });
      } catch { /* not supported */ }
    });
  await page.goto(url + `?play=1&fps=30&prefetch=${prefetch ? 1 : 0}${process.env.WEB_BENCH_QUERY || ""}${extra}`);
  await page.waitForFunction(() => window.panoptes && window.panoptes.firstFrameMs() !== null, { timeout: 30000 });
  const firstFrame = await page.evaluate(() => window.panoptes.firstFrameMs());  // since navigation start
  const marks = await page.evaluate(() => (window.panoptes.marks ? window.panoptes.marks() : {}));
  await new Promise((r) => setTimeout(r, 1500));
  const before = await page.evaluate(() => window.panoptes.traffic());
  for (let i = 0; i < 40; i++) {
    await page.keyboard.press(keys[i % keys.length]);
    await new Promise((r) => setTimeout(r, 330));
  }
  const after = await page.evaluate(() => window.panoptes.traffic());
  const switches = await page.evaluate(() => window.panoptes.switches());
  const loaf = process.env.WEB_BENCH_VERBOSE ? await page.evaluate(() => window.__loaf || []) : [];
  const settings = await page.evaluate(() => { const o = window.panoptes.options; return `nbdecode=${o.nbDecode} nbstride=${o.nbStride}`; });
  await page.close();
  if (process.env.WEB_BENCH_VERBOSE) {
    const d = (k) => after[k] - before[k], b = Math.max(1, d("batches"));
    console.error(`batches ${d("batches")} frames ${d("frames")} per request: fetch ${(d("fetchMs") / Math.max(1, d("requests"))).toFixed(1)} ms; per batch: decode ${(d("decodeMs") / b).toFixed(1)} ms; main thread: demux ${d("demuxMs").toFixed(0)} ms, decoder outputs ${d("outputMs").toFixed(0)} ms, decoders created ${d("warms")}, reused ${d("reused")}`);
  }
  if (process.env.WEB_BENCH_VERBOSE)
    for (const s of switches) if (s.hit && s.ms > 25) {
      const frames = loaf.filter((e) => e.start < s.diag.at + s.ms && e.start + e.duration > s.diag.at);
      console.error(`slow ${s.command} ms=${s.ms.toFixed(1)} ${JSON.stringify(s.diag)} loaf=${JSON.stringify(frames)}`);
    }
  if (process.env.WEB_BENCH_VERBOSE)
    for (const s of switches) if (!s.hit) console.error(`miss ${s.command} ${s.from}->${s.to} ms=${s.ms === null ? "superseded" : s.ms.toFixed(1)} lag=${s.lag} ${JSON.stringify(s.diag)}`);
  // WEB_BENCH_DUMP=FILE appends every switch of the run as a JSON line (pooling runs of separate invocations).
  if (process.env.WEB_BENCH_DUMP)
    fs.appendFileSync(process.env.WEB_BENCH_DUMP, JSON.stringify({ query: (process.env.WEB_BENCH_QUERY || "") + extra, prefetch, load: os.loadavg()[0], switches }) + "\n");
  // A switch overtaken by the next key before it was shown took longer than the 330 ms between keys:
  // it counts as +Infinity in the percentiles (printed as "> 330").
  const shown = switches.filter((s) => s.ms !== null), ms = switches.map((s) => (s.ms === null ? Infinity : s.ms));
  return {
    all: ms, n: switches.length, superseded: switches.length - shown.length, p50: median(ms), p99: pct(ms, 99), max: Math.max(...ms),
    hits: shown.filter((s) => s.hit).length / Math.max(1, switches.length),
    // Of those, shown at the playhead's own frame (the rest showed a frame 1-3 behind it, then caught up).
    atPlayhead: shown.filter((s) => s.hit && s.lag === 0).length / Math.max(1, switches.length),
    decoded: switches.map((s) => s.diag.decodedMs).filter((x) => x !== undefined),
    settings: settings,
    firstFrame, marks, bytesPerSwitch: (after.bytes - before.bytes) / Math.max(1, switches.length),
    requestsPerSwitch: (after.requests - before.requests) / Math.max(1, switches.length),
  };
}

const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox", "--disable-dev-shm-usage"] });
const db = await (await fetch(url + "api/database.json")).json();
const rows = [], rowsData = [];
// Rows: prefetch on with the player's defaults; prefetch on with the other neighbour rule
// (WEB_BENCH_COMPARE, default "&nbdecode=switch", empty to skip), so that one run on an idle machine
// compares them; prefetch off. Runs alternate between the rows (run r of every row, then r + 1) so
// that a change of the machine's load falls on all rows alike.
const compare = process.env.WEB_BENCH_COMPARE ?? "&nbdecode=switch";
const configs = [{ label: "on", prefetch: true, extra: "" }];
if (compare) configs.push({ label: `on, \`${compare.replace(/^&/, "")}\``, prefetch: true, extra: compare });
if (!process.env.WEB_BENCH_ONLY_ON) configs.push({ label: "off", prefetch: false, extra: "" });
const runsOf = configs.map(() => []);
for (let r = 0; r < reps; r++)
  for (const [i, c] of configs.entries()) runsOf[i].push(await run(browser, c.prefetch, c.extra));
for (const [i, { label, prefetch }] of configs.entries()) {
  const runs = runsOf[i];
  const m = (k) => median(runs.map((x) => x[k]));
  // p99 of one run of 40 switches is its worst switch; pooled over the runs it is the 99th percentile
  // of all their switches (120 for 3 runs: the second worst).
  const pooled = pct(runs.flatMap((x) => x.all), 99);
  // Where the time to the first frame goes: each step's median time since navigation start.
  const steps = Object.keys(runs[0].marks).sort((a, b) => runs[0].marks[a] - runs[0].marks[b]);
  const startup = steps.map((k) => `${k} ${median(runs.map((x) => x.marks[k] ?? NaN)).toFixed(0)}`).join(", ");
  const decoded = median(runs.flatMap((x) => x.decoded));
  rowsData.push({ label, prefetch, pooled, decoded, settings: runs[0].settings, hits: m("hits"), atPlayhead: m("atPlayhead"), p50: m("p50"), p99: m("p99"), firstFrame: m("firstFrame"), bytesPerSwitch: m("bytesPerSwitch"), startup });
  const f = (v, d = 1) => (Number.isFinite(v) ? v.toFixed(d) : "> 330");
  const range = (k) => `${f(Math.min(...runs.map((x) => x[k])))}–${f(Math.max(...runs.map((x) => x[k])))}`;
  rows.push(`| ${label} | ${runs[0].n} | ${m("superseded")} | ${f(m("p50"))} | ${f(m("p99"))} (${range("p99")}) | ${f(pooled)} | ${f(m("max"))} | ` +
            `${(100 * m("hits")).toFixed(0)} % | ${m("firstFrame").toFixed(0)} | ${(m("bytesPerSwitch") / 1024).toFixed(1)} | ${m("requestsPerSwitch").toFixed(1)} |`);
}

// Opening a database of 10^6 cameras (no movies: every stream is a "missing" placeholder): time to
// the first drawn frame and to the camera table parsed (navigation ready), the table's size, the
// page's JS heap, and the server's peak memory (VmHWM of `panoptes serve` after the runs).
const big = [];
if (bigUrl) {
  for (let r = 0; r < reps; r++) {
    const page = await browser.newPage();
    await page.goto(bigUrl + "?play=1");
    await page.waitForFunction(() => window.panoptes && window.panoptes.cameraTable() && window.panoptes.firstFrameMs() !== null, { timeout: 180000, polling: 50 });
    const t = await page.evaluate(() => ({ first: window.panoptes.firstFrameMs(), table: window.panoptes.cameraTable() }));
    // Navigation works at that size: Right follows the graph.
    const before = await page.evaluate(() => window.panoptes.state().camera);
    const want = await page.evaluate((c) => window.panoptes.neighbour(c, "right"), before);
    await page.keyboard.press("ArrowRight");
    await page.waitForFunction((c) => window.panoptes.state().camera === c, { timeout: 10000 }, want);
    const heap = (await page.metrics()).JSHeapUsedSize;
    await page.close();
    big.push({ first: t.first, fetched: t.table.loaded, parsed: t.table.parsed, bytes: t.table.bytes, heap });
  }
}
const serverPeakMB = bigPid ? Number((fs.readFileSync(`/proc/${bigPid}/status`, "utf8").match(/VmHWM:\s+(\d+)/) || [0, 0])[1]) / 1024 : NaN;

const version = await browser.version();
await browser.close();
console.log(`Database \`${dbPath}\`: ${db.cameras.count} cameras × ${db.tasks.length} tasks, ${db.frames} frames of ` +
            `${db.image.width}×${db.image.height} at ${db.fps} fps (gop ${db.gop}); ${version} headless, ${reps} runs per row ` +
            `(medians; p99 range over runs); ${os.cpus()[0].model}, ${os.cpus().length} cores, load average at the end ${os.loadavg().map((x) => x.toFixed(1)).join(" ")}.`);
console.log("");
console.log("| prefetch | switches/run | not shown before the next switch | p50 ms | p99 ms (range over runs) | p99 ms, all runs pooled | max ms | shown on the next frame | first frame ms | kB fetched/switch | requests/switch |");
console.log("|---|---|---|---|---|---|---|---|---|---|---|");
for (const r of rows) console.log(r);
// Next to the targets of issue 13 (the prefetch-on row's medians).
const on = rowsData[0];
if (on) {
  const verdict = (ok) => (ok ? "met" : "NOT met");
  console.log("");
  const ms = (v) => (Number.isFinite(v) ? v.toFixed(1) + " ms" : "> 330 ms");
  const off = rowsData.find((x) => !x.prefetch), other = compare ? rowsData[1] : null;
  console.log(`Targets: switch p99 with prefetch < 33 ms: ${ms(on.pooled)} pooled over all runs' switches (${verdict(on.pooled < 33)}; ` +
              `${ms(on.p99)} median of the runs' p99); p50 ${ms(on.p50)}` +
              (other ? `; with \`${compare.replace(/^&/, "")}\`: p50 ${ms(other.p50)}, p99 ${ms(other.pooled)} pooled (${verdict(other.pooled < 33)})` : "") +
              (off ? `; prefetch off: p50 ${ms(off.p50)}, p99 ${ms(off.pooled)} pooled` : "") +
              `; time to first frame ${on.firstFrame.toFixed(0)} ms; ${(on.bytesPerSwitch / 1024).toFixed(1)} kB fetched per switch ` +
              `(player settings: ${on.settings}). ` +
              `Load average during the run: ${os.loadavg()[0].toFixed(1)} (on a loaded machine the tail measures the scheduler, not the player).`);
  if (Number.isFinite(on.decoded)) console.log(`From the key to the new stream's first decoded frame: ${on.decoded.toFixed(1)} ms (median of all switches, prefetch on).`);
  console.log("");
  console.log(`Shown on the next display frame: ${(100 * on.hits).toFixed(0)} %, of the switches ${(100 * on.atPlayhead).toFixed(0)} % at the playhead's own frame, ` +
              `the rest 1-3 frames behind it (then in step).`);
  console.log(`First frame, ms since navigation start (medians, prefetch on): ${on.startup}.`);
}
if (big.length) {
  const m = (k) => median(big.map((x) => x[k]));
  console.log("");
  console.log(`Opening \`${bigPath}\` (${bigPath.match(/\d+$/)[0]} cameras, no movies; ${reps} runs, medians):`);
  console.log("");
  console.log("| first frame ms | camera table fetched ms | parsed, navigation ready ms | table MB | page JS heap MB | serve peak RSS MB |");
  console.log("|---|---|---|---|---|---|");
  console.log(`| ${m("first").toFixed(0)} | ${m("fetched").toFixed(0)} | ${m("parsed").toFixed(0)} | ${(m("bytes") / 1e6).toFixed(1)} | ${(m("heap") / 1e6).toFixed(0)} | ${serverPeakMB.toFixed(0)} |`);
}
