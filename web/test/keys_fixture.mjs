// Test fixture until `panoptes serve` / `export-web` publish api/keys.json themselves (issue 30,
// helper h30keys; format at the top of docs/web.md): the same document built from the C++ key table's
// source (src/player/keys.cpp, its kBindings rows). Its per-mode wording and operations follow the
// desktop's rules as docs/web.md states them (lattice: arrows and PgUp/PgDn walk; panorama and
// lattice: magnify = field of view); the real table from serve replaces it as soon as it answers.
//   node keys_fixture.mjs SRC/player/keys.cpp OUT.json     (or import { keysFixture })
import fs from "node:fs";

const EVENT_KEYS = { Left: ["ArrowLeft"], Right: ["ArrowRight"], Up: ["ArrowUp"], Down: ["ArrowDown"], Space: [" "],
                     Period: ["."], Comma: [","], "Shift+Period": [">"], "Shift+Comma": ["<"], "Shift+Tab": ["Tab"] };
const WALK = { camera_up: "walk_forward", camera_down: "walk_back", camera_left: "walk_left", camera_right: "walk_right",
               axis_up: "walk_up", axis_down: "walk_down" };
const WALK_TEXT = { walk_forward: "walk forward: to the neighbour ahead of the view", walk_back: "walk back",
                    walk_left: "walk left", walk_right: "walk right", walk_up: "walk up (towards the sky)", walk_down: "walk down" };
const FOV = { zoom_in: "fov_narrow", zoom_out: "fov_widen", zoom_reset: "fov_reset" };
const FOV_TEXT = { fov_narrow: "narrow the field of view (also the wheel)", fov_widen: "widen the field of view", fov_reset: "field of view 90 degrees" };
const FRONT_END_ONLY = new Set(["zoom_in", "zoom_out", "zoom_reset", "fullscreen", "screenshot", "record", "help", "toggle_hud", "quit"]);

export function keysFixture(source) {
  const text = fs.readFileSync(source, "utf8");
  const row = /KeyBinding\{"((?:[^"\\]|\\.)*)", Action::(\w+), "((?:[^"\\]|\\.)*)"\}/g;
  const rows = [...text.matchAll(row)].map((m) => ({ desktop: JSON.parse(`"${m[1]}"`), action: m[2], text: JSON.parse(`"${m[3]}"`) }));
  if (rows.length < 20) throw new Error(`${source}: found ${rows.length} key rows, expected the whole table`);
  const actions = {};
  const bindings = rows.map(({ desktop, action, text: t }) => {
    const ops = { sphere: action, panorama: FOV[action] ?? action, lattice: WALK[action] ?? FOV[action] ?? action };
    actions[action] = ops;
    const keys = EVENT_KEYS[desktop] ?? (/^[A-Z]$/.test(desktop) ? [desktop, desktop.toLowerCase()] : [desktop]);
    const b = { desktop, keys, codes: [], action, modes: ["sphere", "panorama", "lattice"], front_end_only: FRONT_END_ONLY.has(action),
                description: { sphere: t, panorama: FOV_TEXT[ops.panorama] ?? t, lattice: WALK_TEXT[ops.lattice] ?? FOV_TEXT[ops.lattice] ?? t } };
    if (desktop === "Tab") b.shift = false;
    if (desktop === "Shift+Tab") b.shift = true;
    return b;
  });
  return {
    version: 1, generated_from: "src/player/keys.cpp (web test fixture)",
    bindings, actions,
    walk: { slots: ["left", "right", "up", "down", "in", "out"], min_cos: 0.5, keep_view: true },
    look: { fov_deg: 90, fov_min_deg: 20, fov_max_deg: 120, pitch_max_deg: 89, key_fov_factor: 1.25, wheel_fov_factor: 1.15 },
    playback: { speed_min: 0.25, speed_max: 8, faster_factor: 2, fine_factor: 1.1, short_run: { shortest_run_s: 4, speed_min: 0.25 } },
    numbering: { camera_first: 0, frame_first: 0, task_first: 1 },
  };
}

/// Makes a puppeteer page get the fixture for api/keys.json when the server has none (a 404): only
/// that URL is intercepted (CDP Fetch with one pattern), every other request goes its way untouched.
export async function provideKeys(page, source) {
  const cdp = await page.target().createCDPSession();
  const body = Buffer.from(JSON.stringify(keysFixture(source))).toString("base64");
  await cdp.send("Fetch.enable", { patterns: [{ urlPattern: "*/api/keys.json*", requestStage: "Response" }] });
  cdp.on("Fetch.requestPaused", async (e) => {
    if (e.responseStatusCode === 404)
      await cdp.send("Fetch.fulfillRequest", { requestId: e.requestId, responseCode: 200, body,
                                               responseHeaders: [{ name: "Content-Type", value: "application/json" }] });
    else await cdp.send("Fetch.continueRequest", { requestId: e.requestId });
  });
}

if (process.argv[1] && process.argv[1].endsWith("keys_fixture.mjs") && process.argv.length >= 4) {
  const [source, out] = process.argv.slice(2);
  fs.writeFileSync(out, JSON.stringify(keysFixture(source), null, 1));
  console.log(`${out}: the key table fixture`);
}
