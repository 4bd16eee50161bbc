#pragma once
// Shared by the fuzz targets: a private scratch directory per process (targets whose API reads
// files write each input there) and the replay driver's contract.
//
// Each target defines LLVMFuzzerTestOneInput. Built with PANOPTES_FUZZ=ON (clang) it links libFuzzer;
// otherwise replay_main.cpp provides main() and the target replays files and directories of inputs
// (ctest fuzz.replay.*: the committed regression inputs and the seeds fuzz_seeds generates).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

namespace panoptes::fuzz {

/// A directory private to this process, removed at exit.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string tmpl = std::string(base && *base ? base : "/tmp") + "/panoptes_fuzz_XXXXXX";
    if (!::mkdtemp(tmpl.data())) std::abort();
    static const std::string keep = tmpl;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(keep, ec);
    });
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

/// Writes bytes to scratch_dir()/name and returns the path.
inline std::filesystem::path write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const auto path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) std::abort();
  return path;
}

inline std::string as_string(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

}  // namespace panoptes::fuzz
