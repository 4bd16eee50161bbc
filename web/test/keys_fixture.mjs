// Test fixture until `panoptes serve` / `export-web` write keys.json themselves (helper h30keys, issue
// 30): generates keys.json from the C++ key table's source (src/player/keys.cpp, its kBindings rows),
// in the format the player reads (web/player/keys.js: {"bindings": [{key, action, description}]}).
//   node keys_fixture.mjs SRC/player/keys.cpp OUT/keys.json
import fs from "node:fs";

const [source, out] = process.argv.slice(2);
const text = fs.readFileSync(source, "utf8");
const row = /KeyBinding\{"((?:[^"\\]|\\.)*)", Action::(\w+), "((?:[^"\\]|\\.)*)"\}/g;
const bindings = [...text.matchAll(row)].map((m) => ({ key: JSON.parse(`"${m[1]}"`), action: m[2], description: JSON.parse(`"${m[3]}"`) }));
if (bindings.length < 20) throw new Error(`${source}: found ${bindings.length} key rows, expected the whole table`);
fs.writeFileSync(out, JSON.stringify({ format: "panoptes-keys", version: 1, generated_from: "src/player/keys.cpp (test fixture)", bindings }, null, 1));
console.log(`${out}: ${bindings.length} key rows`);
