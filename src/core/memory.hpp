#pragma once
// Memory budgets: what a run will need, what this process may use, and the one-line refusal when the
// first does not fit in the second. A run that cannot fit should fail before its first step with the
// numbers, not minutes later with std::bad_alloc or the OOM killer.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace panoptes {

/// Memory this process may still allocate: the smaller of the kernel's MemAvailable and the room left
/// under the cgroup limit (v2 memory.max − memory.current, or v1 limit_in_bytes − usage_in_bytes).
struct MemoryLimit {
  double bytes = -1;   ///< < 0: unknown (no /proc/meminfo and no cgroup limit: the check is skipped)
  std::string source;  ///< e.g. "MemAvailable", "cgroup memory.max"
};

/// Reads /proc/meminfo and the cgroup files of this process. Never throws. The environment variable
/// PANOPTES_MEMORY_LIMIT (bytes, or with a suffix K, M, G, T: powers of 1000) replaces both, for batch
/// systems that do not confine jobs with cgroups.
MemoryLimit available_memory();

/// An itemized estimate of the peak resident memory of one process (rank).
struct MemoryEstimate {
  std::vector<std::pair<std::string, double>> items;  ///< (what, bytes)
  void add(const std::string& what, double bytes) { items.emplace_back(what, bytes); }
  void add(const MemoryEstimate& other) { items.insert(items.end(), other.items.begin(), other.items.end()); }
  double total() const;
  /// "96.1 GB (solver arrays 80.0 GB, receiver traces 16.1 GB)": the total and its largest items.
  std::string describe() const;
};

/// Throws panoptes::Error, in one line naming both numbers, when `estimate` exceeds
/// `limit.bytes / sharing` (sharing = processes of the run on this machine). `what` names the run
/// ("this run"), `override_hint` how to bypass the check (e.g. "pass --force"). Does nothing when
/// the limit is unknown.
void check_memory(const MemoryEstimate& estimate, const MemoryLimit& limit, int sharing, const std::string& what,
                  const std::string& override_hint);
/// The message check_memory() would throw, or "" when the estimate fits.
std::string memory_refusal(const MemoryEstimate& estimate, const MemoryLimit& limit, int sharing,
                           const std::string& what, const std::string& override_hint);

/// Bytes for humans: "512 B", "3.4 MB", "1.8 GB" (powers of 1000).
std::string format_bytes(double bytes);

/// The soft limit on open files of this process, raised to the hard limit first (movies are written
/// with one open file each). Returns -1 when unlimited or unknown.
long long open_file_limit();

/// a·b for non-negative counts, or throws Error("<what>: a x b overflows ...") beyond `limit`.
std::int64_t checked_product(std::int64_t a, std::int64_t b, const std::string& what,
                             std::int64_t limit = INT64_MAX);

}  // namespace panoptes
