// While playing, the frame under the playhead may not be decoded yet (a stream just switched to, a
// slow decoder): the player then shows the newest decoded frame just behind the playhead rather than
// keep the old stream on screen. The C++ engine waits for the frame it needs instead; the page's
// clock runs on meanwhile, so it needs this choice.
//
// A frame the database marks damaged (it fails its checksum, movie identity or position checks) may
// still be decoded and cached - the decoder needs it as a reference for the frames after it - but
// its pixels must never be shown as a good frame: the choice says it is damaged, and the player
// draws the placeholder (web/test/late_frame_test.mjs; the browser test web.packed plays across one).

/// The frame to show in place of `frame`, looking at most `depth` frames behind the playhead (in the
/// direction of play `dir`, wrapping over `frames`): {frame, damaged} for the first one that is
/// decoded (`isDecoded(g)`) or damaged (`isDamaged(g)`), or null when none is, or when the stream's
/// frame `shownFrame` already on screen comes first (nothing newer to show).
export function lateFrame({ frame, dir, frames, shownFrame, isDecoded, isDamaged, depth = 3 }) {
  for (let back = 1; back <= depth; back++) {
    const g = (((frame - back * dir) % frames) + frames) % frames;
    if (g === shownFrame) return null;
    if (isDamaged(g)) return { frame: g, damaged: true };
    if (isDecoded(g)) return { frame: g, damaged: false };
  }
  return null;
}
