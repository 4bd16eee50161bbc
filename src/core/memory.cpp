#include "core/memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace panoptes {

namespace {

// The first number of a small text file, or -1 ("max", missing, unreadable).
double read_number(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  if (!(in >> s) || s == "max") return -1;
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    return used == s.size() && v >= 0 ? v : -1;
  } catch (const std::exception&) {
    return -1;
  }
}

// This process's cgroup v2 path ("0::/some/path"), or "" for cgroup v1 / none.
std::string cgroup_v2_path() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("0::", 0) == 0) return line.substr(3);
  return "";
}

}  // namespace

MemoryLimit available_memory() {
  MemoryLimit out;
  // An explicit limit (batch systems that do not confine jobs with cgroups; tests).
  if (const char* env = std::getenv("PANOPTES_MEMORY_LIMIT"); env && *env) {
    char* end = nullptr;
    double v = std::strtod(env, &end);
    const std::string unit = end ? std::string(end) : "";
    const double scale = unit.empty() || unit == "B" ? 1 : unit == "K" ? 1e3 : unit == "M" ? 1e6 : unit == "G" ? 1e9 : unit == "T" ? 1e12 : -1;
    if (end != env && v >= 0 && scale > 0) return {v * scale, "PANOPTES_MEMORY_LIMIT"};
  }
  {
    std::ifstream in("/proc/meminfo");
    std::string key;
    double kb = 0;
    std::string unit;
    while (in >> key >> kb) {
      std::getline(in, unit);
      if (key == "MemAvailable:") {
        out.bytes = kb * 1024;
        out.source = "MemAvailable";
        break;
      }
    }
  }
  auto consider = [&](double limit, double usage, const char* source) {
    // Limits near 2^63 mean "no limit" on cgroup v1.
    if (limit < 0 || limit > 1e18 || usage < 0) return;
    const double room = std::max(0.0, limit - usage);
    if (out.bytes < 0 || room < out.bytes) {
      out.bytes = room;
      out.source = source;
    }
  };
  // cgroup v2: the limit of the nearest ancestor that has one binds; walk up to the root.
  bool found = false;
  if (const std::string v2 = cgroup_v2_path(); !v2.empty()) {
    for (std::string p = v2;;) {
      const std::string dir = "/sys/fs/cgroup" + (p == "/" ? std::string() : p);
      if (const double limit = read_number(dir + "/memory.max"); limit >= 0) {
        consider(limit, read_number(dir + "/memory.current"), "cgroup memory.max");
        found = true;
        break;
      }
      if (p == "/" || p.empty()) break;
      const auto slash = p.find_last_of('/');
      p = slash == 0 || slash == std::string::npos ? "/" : p.substr(0, slash);
    }
  }
  // cgroup v1 (or hybrid): the memory controller's files, mounted for this process's group.
  if (!found)
    consider(read_number("/sys/fs/cgroup/memory/memory.limit_in_bytes"),
             read_number("/sys/fs/cgroup/memory/memory.usage_in_bytes"), "cgroup memory.limit_in_bytes");
  return out;
}

double MemoryEstimate::total() const {
  double t = 0;
  for (const auto& [what, bytes] : items) t += bytes;
  return t;
}

std::string MemoryEstimate::describe() const {
  auto sorted = items;
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string s = format_bytes(total()) + " (";
  int shown = 0;
  for (const auto& [what, bytes] : sorted) {
    if (shown == 3 || (shown > 0 && bytes < 0.01 * total())) break;
    s += (shown++ ? ", " : "") + what + " " + format_bytes(bytes);
  }
  return s + ")";
}

std::string memory_refusal(const MemoryEstimate& estimate, const MemoryLimit& limit, int sharing,
                           const std::string& what, const std::string& override_hint) {
  if (limit.bytes < 0) return "";
  sharing = std::max(sharing, 1);
  const double per_process = limit.bytes / sharing;
  if (estimate.total() <= per_process) return "";
  std::string have = format_bytes(per_process) + " available (" + limit.source;
  if (sharing > 1) have += " " + format_bytes(limit.bytes) + " shared by " + std::to_string(sharing) + " ranks on this machine";
  have += ")";
  return what + " needs about " + estimate.describe() + " of memory per rank, but this rank has " + have +
         "; make the grid, the images or the rig smaller, use more ranks, or " + override_hint;
}

void check_memory(const MemoryEstimate& estimate, const MemoryLimit& limit, int sharing, const std::string& what,
                  const std::string& override_hint) {
  const std::string why = memory_refusal(estimate, limit, sharing, what, override_hint);
  if (!why.empty()) throw Error(why);
}

std::string format_bytes(double b) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (std::abs(b) >= 1000 && u < 6) b /= 1000, ++u;
  char buf[48];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", b, units[u]);
  return buf;
}

long long open_file_limit() {
  rlimit r{};
  if (::getrlimit(RLIMIT_NOFILE, &r) != 0) return -1;
  if (r.rlim_cur < r.rlim_max) {
    rlimit raised = r;
    raised.rlim_cur = r.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) r = raised;
  }
  if (r.rlim_cur == RLIM_INFINITY) return -1;
  return (long long)r.rlim_cur;
}

std::int64_t checked_product(std::int64_t a, std::int64_t b, const std::string& what, std::int64_t limit) {
  std::int64_t p = 0;
  if (a < 0 || b < 0 || __builtin_mul_overflow(a, b, &p) || p > limit)
    throw Error(what + ": " + std::to_string(a) + " x " + std::to_string(b) + " is more than the limit of " +
                std::to_string(limit));
  return p;
}

}  // namespace panoptes
