// See cinema_view_test.sh (and Cinema:Explorer, the other viewer of the package, shows the images). Arguments: SITE_DIR CHROMIUM NODE_MODULES DATABASE IMAGES [SCREENSHOT].
import { createRequire } from "node:module";
import assert from "node:assert/strict";
import fs from "node:fs";
import http from "node:http";
import path from "node:path";

const [siteDir, chromium, nodeModules, database, imagesArg, screenshot] = process.argv.slice(2);
const images = Number(imagesArg);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");

const types = { ".html": "text/html", ".js": "text/javascript", ".css": "text/css", ".json": "application/json",
                ".csv": "text/csv", ".png": "image/png", ".jpg": "image/jpeg" };
const server = http.createServer((req, res) => {
  const rel = path.normalize(decodeURIComponent(new URL(req.url, "http://x").pathname)).replace(/^(\.\.[/\\])+/, "");
  fs.readFile(path.join(siteDir, rel), (err, data) => {
    if (err) { res.writeHead(404); return res.end(); }
    res.writeHead(200, { "Content-Type": types[path.extname(rel)] || "application/octet-stream" });
    res.end(data);
  });
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}/`;
const d3 = fs.readFileSync(path.join(siteDir, "cinema/lib/d3.v4.min.js"));

const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox", "--disable-dev-shm-usage"] });
let failures = 0;
async function check(name, fn) {
  try {
    await fn();
    console.log(`ok   ${name}`);
  } catch (e) {
    failures++;
    console.log(`FAIL ${name}: ${e.message.split("\n").slice(0, 8).join(" | ")}`);
  }
}

try {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  await page.setRequestInterception(true);
  page.on("request", (r) => {
    const u = r.url();
    if (u.startsWith(base)) return r.continue();
    if (u === "https://d3js.org/d3.v4.min.js") return r.respond({ status: 200, contentType: "text/javascript", body: d3 });
    return r.abort();  // nothing leaves the machine
  });
  await page.setViewport({ width: 900, height: 700 });
  await page.goto(`${base}cinema_view.html?databases=${database}`);

  // The picture shown: its source, and whether it is a loaded image of the database (not empty.png).
  const shown = () => page.evaluate(() => {
    const img = document.querySelector("img.cinemaImage");
    return img ? { src: img.getAttribute("src"), ok: img.complete && img.naturalWidth > 1 && !/empty\.png$/.test(img.src) } : null;
  });
  const settle = async () => page.waitForFunction(() => {
    const img = document.querySelector("img.cinemaImage");
    return img && img.complete;
  }, { timeout: 10000 });

  await check("first screen is an image of the database", async () => {
    await page.waitForFunction(() => document.querySelectorAll("#sliderContainer input[type=range]").length > 0, { timeout: 15000 });
    await settle();
    const s = await shown();
    assert.ok(s && s.ok, `first screen: ${JSON.stringify(s)}`);
    assert.ok(s.src.startsWith(`${database}/image/`), s.src);
  });

  const sliders = await page.evaluate(() => [...document.querySelectorAll("#sliderContainer > div")].map((d) => ({
    name: d.firstChild.textContent, max: Number(d.querySelector("input[type=range]").max) })));
  console.log("sliders:", JSON.stringify(sliders));
  const setSlider = (i, v) => page.evaluate((i, v) => {
    const s = document.querySelectorAll("#sliderContainer input[type=range]")[i];
    s.value = String(v);
    s.dispatchEvent(new Event("input"));
  }, i, v);

  await check("moving each slider changes the picture", async () => {
    assert.ok(sliders.length >= 3, `sliders: ${JSON.stringify(sliders)}`);
    for (let i = 0; i < sliders.length; ++i) {
      assert.ok(sliders[i].max > 0, `slider ${sliders[i].name} has one value`);
      const before = (await shown()).src;
      await setSlider(i, sliders[i].max);
      await settle();
      const after = await shown();
      assert.ok(after.ok && after.src !== before, `slider ${sliders[i].name}: ${before} -> ${JSON.stringify(after)}`);
      await setSlider(i, 0);
      await settle();
    }
  });

  await check(`every one of the ${images} images is reachable from the sliders`, async () => {
    const seen = new Set();
    const walk = async (i) => {
      if (i === sliders.length) {
        await settle();
        const s = await shown();
        assert.ok(s.ok, `no picture at ${JSON.stringify(await page.evaluate(() => [...document.querySelectorAll("#sliderContainer input[type=range]")].map((x) => x.value)))}`);
        seen.add(s.src);
        return;
      }
      for (let v = 0; v <= sliders[i].max; ++v) {
        await setSlider(i, v);
        await walk(i + 1);
      }
    };
    await walk(0);
    assert.equal(seen.size, images);
  });

  if (screenshot) await page.screenshot({ path: screenshot });
  await check("no page errors", async () => assert.deepEqual(errors, []));

  // Cinema:Explorer (same package) reads the same data.csv: its image spread shows the database's
  // images. It loads vtk.js from unpkg.com for 3D artefacts, which Panoptes does not write: refused here.
  await check("Cinema:Explorer shows the images", async () => {
    const ex = await browser.newPage();
    const local = { "https://d3js.org/d3.v5.min.js": "cinema/lib/d3.v5.min.js",
                    "https://cinemascience.github.io/release/CinemaComponents.v2.7.1.min.js": "cinema/lib/CinemaComponents.v2.7.1.min.js",
                    "https://cinemascience.github.io/release/CinemaComponents.v2.7.1.min.css": "cinema/lib/CinemaComponents.v2.7.1.min.css" };
    await ex.setRequestInterception(true);
    ex.on("request", (r) => {
      const u = r.url();
      if (u.startsWith(base)) return r.continue();
      if (local[u]) return r.respond({ status: 200, contentType: u.endsWith(".css") ? "text/css" : "text/javascript",
                                       body: fs.readFileSync(path.join(siteDir, local[u])) });
      return r.abort();
    });
    await ex.setViewport({ width: 1200, height: 800 });
    await ex.goto(`${base}cinema_explorer.html?databases=${database}`);
    await ex.waitForFunction((db) => [...document.querySelectorAll("img")].filter(
      (i) => i.getAttribute("src") && i.getAttribute("src").includes(db + "/image/") && i.complete && i.naturalWidth > 1).length >= 1,
      { timeout: 20000 }, database);
    const n = await ex.evaluate((db) => [...document.querySelectorAll("img")].filter((i) => (i.getAttribute("src") || "").includes(db + "/image/")).length, database);
    assert.ok(await ex.evaluate((n) => new RegExp(`${n} out of ${n} results selected`).test(document.body.innerText), images),
              `explorer did not select all ${images} rows`);
    console.log(`     explorer shows ${n} images on its first page`);
    if (screenshot) await ex.screenshot({ path: screenshot.replace(/\.png$/, "-explorer.png") });
  });
} finally {
  await browser.close();
  server.close();
}
process.exit(failures ? 1 : 0);
