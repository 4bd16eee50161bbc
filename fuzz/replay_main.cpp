// main() for a fuzz target built without libFuzzer: runs LLVMFuzzerTestOneInput on every file named
// on the command line (directories: every file in them, sorted), so the corpora are regression tests
// under any compiler and sanitizer. Exit status 0 when every input ran (a crash ends the process).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// Inputs under a "pending*" directory still crash code another change is fixing: replayed only with
// PANOPTES_FUZZ_PENDING=1 (see the README in such a directory).
bool pending(const std::filesystem::path& p) {
  for (const auto& part : p)
    if (part.string().rfind("pending", 0) == 0) return true;
  return false;
}

int main(int argc, char** argv) {
  const char* with_pending = std::getenv("PANOPTES_FUZZ_PENDING");
  const bool replay_pending = with_pending && std::string(with_pending) == "1";
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path p(argv[i]);
    if (std::filesystem::is_directory(p)) {
      for (const auto& e : std::filesystem::recursive_directory_iterator(p)) {
        if (!e.is_regular_file() || e.path().extension() == ".md") continue;
        if (pending(std::filesystem::relative(e.path(), p)) && !replay_pending) {
          std::fprintf(stderr, "replay: %s skipped (pending a fix; PANOPTES_FUZZ_PENDING=1 replays it)\n", e.path().c_str());
          continue;
        }
        files.push_back(e.path());
      }
    } else if (std::filesystem::is_regular_file(p)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "replay: %s: no such file or directory\n", argv[i]);
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    std::fprintf(stderr, "replay: %s (%zu bytes)\n", f.c_str(), bytes.size());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("replay: %zu inputs ran\n", files.size());
  return files.empty() ? 1 : 0;
}
