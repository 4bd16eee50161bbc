// Screenshot of the web player for docs/web.md:
//   node web/test/screenshot.mjs URL OUT.png CHROMIUM NODE_MODULES   (URL of `panoptes serve out/demo`)
import { createRequire } from "node:module";
import { resolve } from "node:path";

const [url, out, chromium, nodeModules] = process.argv.slice(2);
const puppeteer = createRequire(resolve(nodeModules) + "/")("puppeteer-core");  // NODE_MODULES may be relative
const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox"] });
const page = await browser.newPage();
await page.setViewport({ width: 1000, height: 860 });
await page.goto(url + "?play=1&camera=30&task=2&frame=11");
await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded(), { timeout: 30000 });
for (const key of ["ArrowRight", "ArrowRight", "ArrowUp"]) {
  await new Promise((r) => setTimeout(r, 700));
  await page.keyboard.press(key);
}
await new Promise((r) => setTimeout(r, 900));
await page.keyboard.press(" ");  // pause, so the HUD and the frame agree in the picture
await new Promise((r) => setTimeout(r, 400));
await page.screenshot({ path: out });
await browser.close();
