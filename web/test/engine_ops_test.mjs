// The browser's half of the key table without a browser (issue 43): keys.js's match and refusal rules
// and engine_ops.js's operations against the keys.json the C++ table publishes (`panoptes keys --json`).
//   PANOPTES=build/bin/panoptes node --test web/test/engine_ops_test.mjs
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { parseKeyTable, bindingOf, refusalOf, MODES } from "../player/keys.js";
import { engineOps, makeClock, stepTaskOnAxis, isFrontEndOperation } from "../player/engine_ops.js";

const panoptes = process.env.PANOPTES;
if (!panoptes) throw new Error("set PANOPTES to the panoptes program (it prints keys.json)");
const json = JSON.parse(execFileSync(panoptes, ["keys", "--json"], { encoding: "utf8" }));
const table = parseKeyTable(json);
const press = (key, mods = {}) => ({ key, shiftKey: false, ctrlKey: false, altKey: false, metaKey: false, ...mods });
const actionOf = (e) => bindingOf(e, table)?.action;

test("a modifier is part of the key: Shift+A is not A", () => {
  assert.equal(actionOf(press("a")), "next_axis");
  assert.equal(actionOf(press("A")), "next_axis");  // Caps Lock
  assert.equal(actionOf(press("A", { shiftKey: true })), "previous_axis");
  assert.equal(actionOf(press("Tab", { shiftKey: true })), "previous_task");
  assert.equal(actionOf(press("Tab")), "next_task");
  assert.equal(actionOf(press("L", { shiftKey: true })), "toggle_loop", "an unbound Shift form acts as the plain key");
  assert.equal(actionOf(press(">", { shiftKey: true })), "faster");
  assert.equal(actionOf(press("+", { shiftKey: true })), "zoom_in");
  assert.equal(actionOf(press("a", { ctrlKey: true })), undefined, "Ctrl+A is bound to nothing");
  assert.equal(actionOf(press("Tab", { altKey: true })), undefined);
  assert.equal(actionOf(press("a", { metaKey: true })), undefined);
});

test("every binding is found by its own keys and modifiers", () => {
  for (const r of table.rows) {
    const e = press(r.keys[r.keys.length - 1], { shiftKey: r.shift === true, ctrlKey: r.ctrl === true, altKey: r.alt === true });
    assert.equal(bindingOf(e, table), r, `${r.desktop}: another binding answered`);
    assert.equal(typeof r.repeat, "boolean", `${r.desktop} says whether it repeats`);
  }
});

test("repeat and refusal come from the table", () => {
  const row = (desktop) => table.rows.find((r) => r.desktop === desktop);
  assert.equal(row("Space").repeat, false);
  assert.equal(row("Right").repeat, true);
  assert.equal(refusalOf(table, row("Up"), "sphere"), "no camera above this one");
  assert.equal(refusalOf(table, row("Up"), "lattice"), "no camera that way");
  assert.equal(refusalOf(table, row("Shift+A"), "lattice"), "this key does nothing inside a lattice or along a path");
  assert.equal(refusalOf(table, row("Shift+Period"), "sphere"), "");
});

test("engine_ops.js holds exactly keys.json's engine and dispatch operations", () => {
  const S = { db: { frames: 4, axes: [], tasks: [{ axes: [] }] }, keys: table };
  const { ops } = engineOps({ S, clock: makeClock(S, () => 0), select: () => true, move: () => true, walk: () => true, setLook() {}, notify() {} });
  const engine = new Set(), frontEnd = new Set();
  for (const r of table.rows)
    for (const mode of MODES) {
      const op = json.actions[r.action][mode];
      if (op !== null) (isFrontEndOperation(r, op) ? frontEnd : engine).add(op);
    }
  for (const op of engine) assert.ok(op in ops, `keys.json's engine operation "${op}" has no browser implementation in engine_ops.js`);
  for (const op of Object.keys(ops)) assert.ok(engine.has(op), `engine_ops.js's "${op}" is no engine operation of keys.json`);
  for (const op of frontEnd) assert.ok(!(op in ops), `"${op}" is the front end's (player.js OPS)`);
});

test("A and Shift+A turn the active axis both ways; PageUp keeps the other axes", () => {
  // Tasks of a 3 x 2 product, the first axis varying fastest (synth-db --axes 3x2).
  const tasks = [];
  for (let t = 0; t < 6; t++) tasks.push({ axes: [{ axis: "isovalue", index: t % 3 }, { axis: "opacity", index: Math.floor(t / 3) }] });
  const db = { frames: 4, axes: [{ name: "isovalue" }, { name: "opacity" }], tasks };
  const S = { db, keys: table, axis: 0, camera: 0, task: 1, playing: false, anchorFrame: 0, anchorTime: 0, loop: true, dir: 1, speed: 1, fps: 30 };
  const selected = [];
  const select = (c, t) => { if (t < 0 || t === S.task) return false; selected.push(t); S.task = t; return true; };
  const { ops } = engineOps({ S, clock: makeClock(S, () => 0), select, move: () => false, walk: () => false, setLook() {}, notify() {} });
  assert.equal(ops.previous_axis(), true);
  assert.equal(S.axis, 1, "Shift+A from the first axis wraps to the last");
  assert.equal(ops.axis_up(), true);
  assert.deepEqual(selected, [4], "opacity 0 -> 1, isovalue stays 1");
  assert.equal(ops.axis_up(), false, "the end of the opacity axis is refused");
  assert.equal(ops.next_axis(), true);
  assert.equal(S.axis, 0);
  assert.equal(stepTaskOnAxis(db, 4, "isovalue", 1), 5);
  assert.equal(stepTaskOnAxis(db, 5, "isovalue", 1), -1);
  S.db = { ...db, axes: [] };
  assert.equal(ops.next_axis(), false, "without axes A is refused");
});
