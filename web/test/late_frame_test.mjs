// The player's choice of a late frame while playing (web/player/late_frame.js), without a browser:
//   node --test web/test/late_frame_test.mjs
// The CI run of stop 52 caught web.packed showing frame 2 of the damaged stream as a good frame: the
// playhead had reached frame 3 before it was decoded, and the frame just behind it - decoded, since
// the decoder needs it as a reference - was drawn with status "ok".
import { test } from "node:test";
import assert from "node:assert/strict";
import { lateFrame } from "../player/late_frame.js";

const decoded = (...fs) => (g) => fs.includes(g);
const none = () => false;

test("the newest decoded frame behind the playhead", () => {
  assert.deepEqual(lateFrame({ frame: 5, dir: 1, frames: 10, shownFrame: null, isDecoded: decoded(2, 3), isDamaged: none }),
                   { frame: 3, damaged: false });
  assert.equal(lateFrame({ frame: 5, dir: 1, frames: 10, shownFrame: null, isDecoded: decoded(1), isDamaged: none }), null,
               "at most three frames behind");
});

test("a damaged frame behind the playhead is shown as damaged, never as its decoded pixels", () => {
  const damaged = (g) => g === 2;
  assert.deepEqual(lateFrame({ frame: 3, dir: 1, frames: 4, shownFrame: 1, isDecoded: decoded(1, 2), isDamaged: damaged }),
                   { frame: 2, damaged: true });
  // Once its placeholder is on screen, nothing newer than it is decoded: keep it.
  assert.equal(lateFrame({ frame: 3, dir: 1, frames: 4, shownFrame: 2, isDecoded: decoded(1, 2), isDamaged: damaged }), null);
});

test("the frame already on screen ends the search", () => {
  assert.equal(lateFrame({ frame: 5, dir: 1, frames: 10, shownFrame: 4, isDecoded: decoded(3, 4), isDamaged: none }), null);
});

test("backward play looks ahead of the playhead, and the search wraps", () => {
  assert.deepEqual(lateFrame({ frame: 8, dir: -1, frames: 10, shownFrame: null, isDecoded: decoded(9, 7), isDamaged: none }),
                   { frame: 9, damaged: false });
  assert.deepEqual(lateFrame({ frame: 0, dir: 1, frames: 10, shownFrame: null, isDecoded: decoded(8), isDamaged: none }),
                   { frame: 8, damaged: false });
});
