#pragma once
// The one UTC time stamp: manifests' creation and resume times, the web server's log lines.
#include <ctime>
#include <string>

namespace panoptes {

/// `t` (default: now) as ISO 8601 UTC to the second, e.g. "2026-11-21T22:40:00Z".
std::string utc_iso8601(std::time_t t);
inline std::string utc_now_iso8601() { return utc_iso8601(std::time(nullptr)); }

}  // namespace panoptes
