// Screenshot of the web player inside a 360° database for docs/web.md:
//   node web/test/screenshot_look.mjs URL OUT.png CHROMIUM NODE_MODULES "QUERY" [KEYS...]
// e.g. QUERY "?play=0&camera=4&frame=16&yaw=-40&pitch=-10", KEYS ArrowUp (each pressed, then paused).
import { createRequire } from "node:module";
import { resolve } from "node:path";

const [url, out, chromium, nodeModules, query = "", ...keys] = process.argv.slice(2);
const puppeteer = createRequire(resolve(nodeModules) + "/")("puppeteer-core");  // NODE_MODULES may be relative
const browser = await puppeteer.launch({ executablePath: chromium, headless: true,
  args: ["--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"] });
const page = await browser.newPage();
await page.setViewport({ width: 1100, height: 700 });
await page.goto(url + query);
await page.waitForFunction(() => window.panoptes && window.panoptes.shown() && window.panoptes.camerasLoaded() && window.panoptes.keys(), { timeout: 30000 });
for (const key of keys) {
  await page.keyboard.press(key);
  await new Promise((r) => setTimeout(r, 800));
}
await new Promise((r) => setTimeout(r, 800));
await page.screenshot({ path: out });
console.log(JSON.stringify(await page.evaluate(() => window.panoptes.state())));
await browser.close();
