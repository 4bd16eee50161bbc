// web/player/legend.js against the same cases as the C++ legend (src/player/legend_test.cpp,
// Legend.ScaleModeChangeAndSharedReference): the browser must name the scale, its factor and a shared
// reference exactly as the window does (issue 41). Run: node --test web/test/legend_scale_test.mjs
import { test } from "node:test";
import assert from "node:assert/strict";
import { taskLegend, legendScaleText, legendChangeText, legendNumber } from "../player/legend.js";

const pwave = { colour: [[0, 0.9, 0.35, 0.05], [1, 1.0, 0.8, 0.4]], extinction: [[0, 0], [0.1, 0], [1, 0.5]], absolute_value: true };
function seismicLike() {
  return {
    time_units: "s",
    fields: [{ name: "phi_p", units: "1/s", references: [0.5, 2.0], reference_mode: "snapshot" },
             { name: "phi_s", units: "1/s", references: [4.0, 4.0], reference_mode: "running" }],
    tasks: [
      { id: 0, name: "p-wave", method: "volume", fields: ["phi_p"],
        parameters: { window: [0, 1], relative: true, transfer_function: pwave } },
      { id: 1, name: "p+s", method: "volume", fields: ["phi_p", "phi_s"],
        parameters: { window: [0, 1], relative: true, window2: [0, 0.5], relative2: true, scale: "shared",
                      transfer_function: pwave, transfer_function2: pwave } },
    ],
  };
}

test("the scale mode and its change since the previous frame", () => {
  const db = seismicLike();
  const p0 = taskLegend(db, 0, 0)[0];
  assert.equal(p0.scale, "snapshot");
  assert.equal(legendScaleText(p0), "per snapshot");
  const p1 = taskLegend(db, 0, 1)[0];
  assert.equal(p1.change, 4);
  assert.equal(legendScaleText(p1), "per snapshot: x4 since the previous frame");
});

test("a shared two-field scale multiplies the larger reference", () => {
  const db = seismicLike();
  const ps = taskLegend(db, 1, 0);
  assert.equal(ps.length, 2);
  assert.equal(ps[0].shared, true);
  assert.equal(ps[0].hi, 4);
  assert.equal(ps[1].hi, 2);
  assert.equal(legendScaleText(ps[1], "phi_p"), "running max, shared with phi_p");
  assert.equal(taskLegend(db, 1, 1)[0].change, 1);
  db.tasks[1].parameters.scale = "own";
  assert.equal(taskLegend(db, 1, 0)[0].hi, 0.5);
});

test("older databases: the mode from the running-maximum note, absolute windows name none", () => {
  const db = seismicLike();
  delete db.fields[0].reference_mode;
  assert.equal(taskLegend(db, 0, 0)[0].scale, "snapshot");
  db.provenance = { extra: { "insitu.running_max": "0.5 4" } };
  assert.equal(taskLegend(db, 0, 0)[0].scale, "running");
  db.tasks[0].parameters.relative = false;
  assert.equal(legendScaleText(taskLegend(db, 0, 0)[0]), "");
});

test("fixed scales: the configured value in every frame, named fixed, never a change", () => {
  const db = seismicLike();
  db.fields[0] = { name: "phi_p", units: "1/s", references: [5e-5, 5e-5, 5e-5], reference_mode: "fixed" };
  db.fields[1] = { name: "phi_s", units: "1/s", references: [1.5e-4, 1.5e-4, 1.5e-4], reference_mode: "fixed" };
  db.provenance = { extra: { "insitu.running_max": "0 0" } };
  for (let frame = 0; frame < 4; ++frame) {
    const [p] = taskLegend(db, 0, frame);
    assert.equal(p.scale, "fixed");
    assert.equal(p.physical, true);
    assert.equal(legendNumber(p.hi), "5.00e-05");
    assert.equal(legendScaleText(p), "fixed");
    assert.equal(legendChangeText(p), "");
  }
  db.tasks[1].parameters.window = [0, 0.33];
  db.tasks[1].parameters.window2 = [0, 1];
  const ps = taskLegend(db, 1, 2);
  assert.equal(legendNumber(ps[0].hi), "4.95e-05");
  assert.equal(legendNumber(ps[1].hi), "1.50e-04");
  assert.equal(legendScaleText(ps[0], "phi_s"), "fixed, shared with phi_s");
});
