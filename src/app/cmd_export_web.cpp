// `panoptes export-web DB OUT`: the web player and the database as a static site (docs/web.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "app/command.hpp"
#include "web/server.hpp"
#include "web/site_export.hpp"

namespace cmd_export_web {  // named, not anonymous: the unity build joins the command units

struct Args {
  std::string db, out;
  bool link = false, overwrite = false;
};

void run(const Args& a) {
  using namespace panoptes;
  const bool tty = ::isatty(STDERR_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  const auto summary = web::export_site(a.db, a.out, web::find_player_dir(),
                                        a.link ? web::DatabaseCopy::link : web::DatabaseCopy::copy, a.overwrite,
                                        [&](std::int64_t done, std::int64_t total) {
                                          if (!tty) return;
                                          std::fprintf(stderr, "\rexport-web: %lld / %lld streams", (long long)done,
                                                       (long long)total);
                                          std::fflush(stderr);
                                        });
  if (tty) std::fprintf(stderr, "\n");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s: the web player, %lld of %lld streams indexed, %s (%.1f MB copied) in %.2f s\n", a.out.c_str(),
              (long long)summary.indexed, (long long)summary.streams, a.link ? "db/ links to the database" : "database copied",
              summary.bytes_copied / 1e6, s);
  if (summary.indexed < summary.streams)
    std::printf("note: %lld streams are missing or unreadable; the player shows a placeholder for them\n",
                (long long)(summary.streams - summary.indexed));
  if (summary.stream_index.is_null()) {
    std::printf("host it with any static web server, e.g.: cd %s && python3 -m http.server 8000\n", a.out.c_str());
  } else {
    // The player reads a packed database by byte ranges of its packs; python3 -m http.server ignores
    // Range and would send whole packs for every request.
    std::printf("packed database: %zu stream index file(s) in api/streams, packs in db/packs; host it with a static "
                "server or object store that honours HTTP Range requests (nginx, Apache, caddy, S3, a CDN; not "
                "python3 -m http.server)\n",
                summary.stream_index["shards"].size());
  }
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "export-web",
      "Write the web player and a database as a static site (OUT/index.html, OUT/api/*.json, OUT/db/) that any "
      "static web server can host");
  sub->add_option("DB", args->db, "Database directory")->required()->check(CLI::ExistingDirectory);
  sub->add_option("OUT", args->out, "Output directory of the site")->required();
  sub->add_flag("--link", args->link, "Make OUT/db a symbolic link to the database instead of copying the movies");
  sub->add_flag("--overwrite", args->overwrite, "Write into an OUT that is not empty");
  sub->callback([args] { run(*args); });
});

}  // namespace
