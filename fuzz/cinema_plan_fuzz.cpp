// The whole Cinema import plan (issue 44, point 5): a data.csv as found in the wild, with an image at
// every safe relative path its cells name (a valid 2x2 PNG, at most 32 files), read by plan_import():
// the producer's convention decided from the columns, the file layout and the paths (ParaView,
// Ascent, cinema_python), time columns (time, timestep), measure columns, second image columns,
// non-image layers and Static cameras. A crash, a sanitizer report, a hang or unbounded memory is a
// finding; every exception (a refusal) is accepted.
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "cinema/csv.hpp"
#include "cinema/import.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

// A 2x2 RGB PNG (zlib-compressed, valid CRCs).
const unsigned char kPng[] = {0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x02, 0x00, 0x00, 0x00, 0xfd, 0xd4, 0x9a, 0x73, 0x00, 0x00, 0x00, 0x10, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0x00, 0x44, 0x0c, 0x10, 0x0a, 0x00, 0x1f, 0xee, 0x03, 0xfd, 0x8b, 0x5f, 0x14, 0xd4, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

bool safe_relative(const std::string& p) {
  if (p.empty() || p.size() > 120 || p[0] == '/' || p.find("..") != std::string::npos) return false;
  for (char c : p)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '/' || c == '_' || c == '-' || c == '.' || c == '='))
      return false;
  return p.size() > 4 && (p.ends_with(".png") || p.ends_with(".npz") || p.ends_with(".jpg"));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  namespace fs = std::filesystem;
  if (size > 64 * 1024) return 0;
  const fs::path cdb = fuzz::scratch_dir() / "in.cdb";
  std::error_code ec;
  fs::remove_all(cdb, ec);
  fs::create_directories(cdb, ec);
  const std::string text = fuzz::as_string(data, size);
  {
    std::ofstream out(cdb / "data.csv", std::ios::binary);
    out << text;
  }
  try {
    const cinema::CsvTable t = cinema::parse_csv(text, "data.csv");
    int files = 0;
    for (const auto& row : t.rows)
      for (const std::string& cell : row)
        if (files < 32 && safe_relative(cell)) {
          fs::create_directories((cdb / cell).parent_path(), ec);
          std::ofstream(cdb / cell, std::ios::binary).write(reinterpret_cast<const char*>(kPng), sizeof kPng);
          ++files;
        }
    (void)cinema::plan_import(cdb);
  } catch (const std::exception&) {
  }
  return 0;
}
