#pragma once
// Scanning H.264 Annex B byte streams (NAL units separated by 00 00 01 start codes, as libx264 writes
// its packets), shared by the code that edits encoder output before it is muxed.
#include <cstdint>

namespace panoptes::video {

/// Index of the first 3-byte start code 00 00 01 in d[from, n), or n if there is none.
inline int next_start_code(const std::uint8_t* d, int n, int from) {
  for (int k = from; k + 2 < n; ++k)
    if (d[k] == 0 && d[k + 1] == 0 && d[k + 2] == 1) return k;
  return n;
}

/// Whether a packet whose first start code is at `first` is Annex B: it begins with that start code
/// (3 bytes) or with its zero_byte (4 bytes).
inline bool is_annex_b(const std::uint8_t* d, int first) { return first == 0 || (first == 1 && d[0] == 0); }

}  // namespace panoptes::video
