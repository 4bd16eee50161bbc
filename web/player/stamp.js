// Reads the machine-readable (camera, task, frame) stamp of synthetic frames from RGBA pixels:
// the same code as src/core/frame_stamp.cpp (10 x 8 black/white blocks, sync nibble 1010,
// camera 24 bits, task 16, frame 20, CRC-16/CCITT-FALSE), so tests can check what the canvas shows.
export const STAMP_COLUMNS = 10, STAMP_ROWS = 8;

/// Block size of the stamp in a frame of width x height.
export function stampBlock(width, height) {
  return Math.max(4, Math.floor(Math.min(width, height) / 64));
}

function crc16(bytes) {
  let crc = 0xffff;
  for (const byte of bytes) {
    crc ^= byte << 8;
    for (let b = 0; b < 8; b++) crc = crc & 0x8000 ? ((crc << 1) ^ 0x1021) & 0xffff : (crc << 1) & 0xffff;
  }
  return crc;
}

/// Decodes the stamp from `rgba` (Uint8ClampedArray of a `stride`-pixel wide image whose top-left
/// is the frame's top-left) for a frame of width x height; null if there is no valid stamp.
export function readStamp(rgba, stride, width, height) {
  const block = stampBlock(width, height);
  const lo = Math.floor(block / 4), hi = block - Math.floor(block / 4);
  const bits = [];
  for (let i = 0; i < STAMP_COLUMNS * STAMP_ROWS; i++) {
    const bx = (i % STAMP_COLUMNS) * block, by = Math.floor(i / STAMP_COLUMNS) * block;
    let sum = 0, n = 0;
    for (let y = by + lo; y < by + hi; y++) {
      for (let x = bx + lo; x < bx + hi; x++) {
        const p = 4 * (y * stride + x);
        sum += (77 * rgba[p] + 150 * rgba[p + 1] + 29 * rgba[p + 2]) >> 8;
        n++;
      }
    }
    const mean = Math.floor(sum / n);
    if (mean > 80 && mean < 176) return null;
    bits.push(mean >= 176 ? 1 : 0);
  }
  const bytes = [];
  for (let k = 0; k < 8; k++) {
    let v = 0;
    for (let b = 0; b < 8; b++) v = (v << 1) | bits[8 * k + b];
    bytes.push(v);
  }
  let crc = 0;
  for (let b = 64; b < 80; b++) crc = (crc << 1) | bits[b];
  if (bits[0] !== 1 || bits[1] !== 0 || bits[2] !== 1 || bits[3] !== 0 || crc16(bytes) !== crc) return null;
  const bit = (from, count) => {
    let v = 0;
    for (let b = from; b < from + count; b++) v = v * 2 + bits[b];
    return v;
  };
  return { camera: bit(4, 24), task: bit(28, 16), frame: bit(44, 20) };
}
