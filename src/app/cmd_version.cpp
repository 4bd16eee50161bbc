// `panoptes version`: prints the version and the libraries Panoptes was built with.
#include <cstdio>

extern "C" {
#include <libavcodec/avcodec.h>
}

#include "app/command.hpp"
#include "core/version.hpp"

namespace cmd_version {  // named, not anonymous: the unity build joins the command units
panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto* sub = root.add_subcommand("version", "Print the Panoptes version and the versions of its libraries");
  sub->callback([] {
    std::printf("panoptes %s\nlibavcodec %s\n", panoptes::kVersion, AV_STRINGIFY(LIBAVCODEC_VERSION));
  });
});
}  // namespace
