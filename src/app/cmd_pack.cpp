// `panoptes pack DB [OUT]` and `panoptes unpack DB [OUT]`: a database converted between its two
// layouts (docs/formats.md, Packed layout), every frame copied as stored (bitwise equal packets).
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include "app/command.hpp"
#include "core/error.hpp"
#include "store/pack_convert.hpp"

namespace cmd_pack {  // named, not anonymous: the unity build joins the command units

using namespace panoptes;

struct Args {
  std::string db, out;
};

void convert(const Args& a, bool pack) {
  // Default target beside the source: the source stays untouched until the user replaces it.
  std::string out = a.out;
  if (out.empty()) {
    std::string base = a.db;
    while (base.size() > 1 && base.back() == '/') base.pop_back();
    out = base + (pack ? ".packed" : ".files");
  }
  const bool tty = ::isatty(2);
  const auto progress = [&](std::int64_t done, std::int64_t total) {
    if (tty) std::fprintf(stderr, "\r%s streams: %lld / %lld", pack ? "packing" : "unpacking", (long long)done, (long long)total);
  };
  if (pack)
    store::pack_database(a.db, out, progress);
  else
    store::unpack_database(a.db, out, progress);
  if (tty) std::fprintf(stderr, "\r\033[K");
  std::printf("%s -> %s\n", a.db.c_str(), out.c_str());
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  for (const bool pack : {true, false}) {
    auto args = std::make_shared<Args>();
    auto* sub = root.add_subcommand(
        pack ? "pack" : "unpack",
        pack ? "Convert a database with one movie file per stream into the packed layout (per rank and segment one "
               "pack file + index; docs/formats.md). Frames are copied as stored, not re-encoded"
             : "Convert a packed database into one fragmented MP4 file per stream (its movie pattern). Frames are "
               "copied as stored, not re-encoded");
    sub->add_option("DB", args->db, "Database directory (holding panoptes.json)")->required();
    sub->add_option("OUT", args->out,
                    std::string("New (or empty) directory for the converted database; default DB") +
                        (pack ? ".packed" : ".files"));
    sub->callback([args, pack] { convert(*args, pack); });
  }
});

}  // namespace cmd_pack
