// The value under the pointer of a slice task (issue 41), out of player.js: the shown decoded frame's
// pixel under the pointer (drawn into a 1-pixel canvas: the view canvas is never read back), turned
// into a value by the table database.json publishes (readout.js), shown beside the pointer.
import { readPixel, readingText } from "./readout.js";

/// Installs the hover readout on `canvas`; returns readoutAt(x, y) (the reading of a frame pixel, for
/// the test API) and updateReadout() (call when the shown frame changes).
export function installReadoutHover({ S, canvas, cache, isLookView }) {
  const readoutEl = document.getElementById("readout");
  let hover = null, readoutKey = "", readoutCanvas = null;
  /// The reading of frame pixel (x, y) of the shown frame: {text, kind, value, rgb}, or null.
  function readoutAt(x, y) {
    const sh = S.shown, task = S.db && sh && S.db.tasks[sh.task], vf = S.shownKey && cache.map.get(S.shownKey);
    if (!task || !task.readout || !vf || isLookView() || sh.status !== "ok") return null;
    if (!(x >= 0 && y >= 0 && x < S.db.image.width && y < S.db.image.height)) return null;
    readoutCanvas ??= document.createElement("canvas");
    readoutCanvas.width = readoutCanvas.height = 1;
    const g = readoutCanvas.getContext("2d", { willReadFrequently: true });
    g.drawImage(vf, x, y, 1, 1, 0, 0, 1, 1);
    const rgb = Array.from(g.getImageData(0, 0, 1, 1).data.slice(0, 3));
    const r = readPixel(S.db, S.cams, sh.task, sh.frame, sh.camera, x, y, rgb);
    return r && { text: readingText(r), kind: r.kind, value: r.value, resolution: r.resolution, lo: r.bar.lo, hi: r.bar.hi, rgb, x, y };
  }
  function updateReadout() {
    const x = hover ? Math.floor((hover.cx - S.panX) / S.zoom) : -1, y = hover ? Math.floor((hover.cy - S.panY) / S.zoom) : -1;
    const key = hover ? `${S.shownKey}|${S.task}|${x},${y}` : "";
    if (key === readoutKey) return;
    readoutKey = key;
    S.readout = hover ? readoutAt(x, y) : null;
    readoutEl.hidden = !S.readout;
    if (!S.readout) return;
    readoutEl.textContent = S.readout.text;
    readoutEl.classList.toggle("none", S.readout.kind === "none");
    // Beside the pointer, on the side with room (right and below, else left / above), as the desktop.
    const st = canvas.parentElement.getBoundingClientRect(), left = hover.px > st.width * 0.55, up = hover.py > st.height * 0.8;
    readoutEl.style.left = `${hover.px + (left ? -16 : 16)}px`;
    readoutEl.style.top = `${hover.py + (up ? -16 : 16)}px`;
    readoutEl.style.transform = `translate(${left ? "-100%" : "0"}, ${up ? "-100%" : "0"})`;
  }
  canvas.addEventListener("pointermove", (e) => {
    const r = canvas.getBoundingClientRect(), st = canvas.parentElement.getBoundingClientRect();
    hover = { cx: ((e.clientX - r.left) / r.width) * canvas.width, cy: ((e.clientY - r.top) / r.height) * canvas.height,
              px: e.clientX - st.left, py: e.clientY - st.top };
    updateReadout();
  });
  canvas.addEventListener("pointerleave", () => { hover = null; updateReadout(); });
  return { readoutAt, updateReadout };
}
