// One key script through the web player (headless Chromium), printed as one "camera task frame axis
// shell" row per script line (OUT) and the words of each refused key ("-" for none; OUT.refusals), for
// same_keys.sh to compare with `play --headless`, the window and Python's Player.
//   node same_keys.mjs CHROMIUM NODE_MODULES SCRIPT URL START_CAMERA OUT [URL START_CAMERA OUT ...]
// (one browser for every database: its start-up is most of the leg's time).
// SCRIPT holds `t=... key=NAME` lines (the desktop's key names); each is pressed as the browser's key
// and, once the player shows what it selected, the selection is written out.
import { createRequire } from "node:module";
import fs from "node:fs";

const [chromium, nodeModules, scriptFile, ...runs] = process.argv.slice(2);
const require = createRequire(nodeModules + "/");
const puppeteer = require("puppeteer-core");

// Desktop key names (player/keys.cpp) → puppeteer's key names, with Shift where the name says so.
const named = { Up: "ArrowUp", Down: "ArrowDown", Left: "ArrowLeft", Right: "ArrowRight", Period: ".", Comma: ",",
                Space: " ", "Shift+Period": ">", "Shift+Comma": "<" };
function browserKey(name) {
  if (named[name]) return { key: named[name], shift: false };
  if (name.startsWith("Shift+")) return { key: name.slice(6), shift: true };
  return { key: name.length === 1 ? name.toLowerCase() : name, shift: false };
}
const keys = fs.readFileSync(scriptFile, "utf8").split("\n").map((l) => l.match(/\bkey=(\S+)/)).filter(Boolean).map((m) => m[1]);

const browser = await puppeteer.launch({
  executablePath: chromium, headless: true,
  args: ["--no-sandbox", "--disable-dev-shm-usage", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
let code = 0;
for (let r = 0; r + 2 < runs.length; r += 3) {
  const [url, start, outFile] = runs.slice(r, r + 3);
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 800, height: 500 });
    const errors = [];
    page.on("pageerror", (e) => errors.push(e.message));
    await page.goto(`${url}?play=0&camera=${start}`);
    await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded() && window.panoptes.keys(), { timeout: 20000 });
    const rows = [], refusals = [];
    for (const name of keys) {
      const { key, shift } = browserKey(name);
      if (shift) await page.keyboard.down("Shift");
      await page.keyboard.press(key);
      if (shift) await page.keyboard.up("Shift");
      // Settled: what is drawn is what is selected (a key that changes nothing settles at once).
      await page.waitForFunction(() => {
        const s = window.panoptes.state(), w = window.panoptes.shown();
        return w && w.camera === s.camera && w.task === s.task && w.frame === s.frame;
      }, { timeout: 10000 }).catch(() => {});
      const s = await page.evaluate(() => ({ state: window.panoptes.state(), shown: window.panoptes.shown() }));
      rows.push(`${s.shown.camera} ${s.shown.task} ${s.shown.frame} ${s.state.axis} ${s.state.shell}`);
      refusals.push(s.state.refusal || "-");
      if (s.state.playing) throw new Error(`key ${name} started playback`);
    }
    if (errors.length) throw new Error(`page errors: ${errors.join(" | ")}`);
    fs.writeFileSync(outFile, rows.join("\n") + "\n");
    fs.writeFileSync(outFile + ".refusals", refusals.join("\n") + "\n");
    await page.close();
  } catch (e) {
    console.log(`same_keys.mjs: ${url}: ${e.message}`);
    code = 1;
  }
}
await browser.close();
process.exit(code);
