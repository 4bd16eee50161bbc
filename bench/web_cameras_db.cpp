// web_cameras_db OUT CAMERAS: the manifest and camera table of a synthetic database with CAMERAS
// cameras (Fibonacci sphere, ring graph, one task, one frame) and no movies, for web_bench's
// measurement of how the web player opens a database of 10^6 cameras (every stream then plays as the
// "missing" placeholder; what is measured is database.json + camera table, not decoding).
// Writing 10^6 movies would take hours; the player never touches a movie before it is needed.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "store/manifest.hpp"
#include "store/synthetic.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: web_cameras_db OUT CAMERAS\n");
    return 2;
  }
  try {
    namespace store = panoptes::store;
    const std::filesystem::path out = argv[1];
    store::SyntheticOptions o;
    o.cameras = std::stoi(argv[2]);
    o.tasks = 1;
    o.frames = 1;
    o.title = "web_bench: " + std::string(argv[2]) + " cameras, no movies";
    const auto t0 = std::chrono::steady_clock::now();
    store::Manifest m = store::synthetic_manifest(o);
    m.status = store::Status::complete;
    m.frames_written = 1;
    std::filesystem::create_directories(out);
    store::write_manifest_atomic(out / store::kManifestFileName, m);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "web_cameras_db: %s: %d cameras written in %.1f s\n", out.c_str(), o.cameras, s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "web_cameras_db: error: %s\n", e.what());
    return 1;
  }
}
