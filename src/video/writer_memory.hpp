#pragma once
// Memory of movie writers, for resource checks before a run: scaled from the measurements of
// docs/formats.md at 920×896 (resident growth per open writer: ~1.1 MB intra-only, gop 1; ~25 MB for
// a writer that keeps a P-frame encoder, gop > 1; ~3.5 MB for each encoder of the shared intra-only
// pool, about one per thread that encodes).
namespace panoptes::video {

/// Bytes one open MovieWriter of frames of `pixels` holds between appends.
double open_writer_bytes(double pixels, int gop);
/// Bytes one x264 encoder of the intra-only pool holds (frames of `pixels`); count one per encoding thread.
double live_encoder_bytes(double pixels);

}  // namespace panoptes::video
