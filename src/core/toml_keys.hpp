#pragma once
// Typed reading of keys from a parsed TOML configuration, with one error format for every config
// reader (the seismic solver's and the in-situ engine's): "FILE: KEY: what was expected".
// Header-only so that only the modules that parse TOML (and link tomlplusplus) pull in toml++.
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace panoptes::toml_keys {

/// Where the configuration came from (a path, or a name such as "<string>"), for error messages.
struct Source {
  std::string file;
  /// Throws FileError(file, "KEY: WHAT").
  [[noreturn]] void fail(const std::string& key, const std::string& what) const { throw FileError(file, key + ": " + what); }
};

/// Refuses any key of `t` outside `allowed`; `where` is the table's dotted path ("" for the root).
inline void only_keys(const Source& c, const toml::table& t, const std::string& where,
                      const std::set<std::string>& allowed) {
  for (const auto& [k, v] : t) {
    (void)v;
    if (allowed.count(std::string(k.str()))) continue;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    c.fail(where.empty() ? std::string(k.str()) : where + "." + std::string(k.str()),
           "unknown key (expected one of: " + list + ")");
  }
}

/// The integer at `key` (`where` is the key's prefix, e.g. "grid."), `def` when absent.
inline long long integer(const Source& c, const toml::table& t, const std::string& key, const std::string& where,
                         long long def, bool required = false) {
  const auto* n = t.get(key);
  if (!n) {
    if (required) c.fail(where + key, "missing (an integer is required)");
    return def;
  }
  if (auto v = n->value_exact<std::int64_t>()) return *v;
  c.fail(where + key, "expected an integer");
}

/// An integer key that must fit an int field in [lo, hi]: checked before narrowing (4294967336 is not 40).
inline int int_in(const Source& c, const toml::table& t, const std::string& key, const std::string& where,
                  long long def, long long lo, long long hi, bool required = false) {
  const long long v = integer(c, t, key, where, def, required);
  if (v < lo || v > hi)
    c.fail(where + key, std::to_string(v) + " is out of range (expected an integer in " + std::to_string(lo) + " .. " +
                            std::to_string(hi) + ")");
  return int(v);
}

/// The boolean at `key`, `def` when absent.
inline bool boolean(const Source& c, const toml::table& t, const std::string& key, const std::string& where,
                    bool def) {
  const auto* n = t.get(key);
  if (!n) return def;
  if (auto v = n->value_exact<bool>()) return *v;
  c.fail(where + key, "expected true or false");
}

/// The string at `key`, `def` when absent.
inline std::string str(const Source& c, const toml::table& t, const std::string& key, const std::string& where,
                       const std::string& def, bool required = false) {
  const auto* n = t.get(key);
  if (!n) {
    if (required) c.fail(where + key, "missing (a string is required)");
    return def;
  }
  if (auto v = n->value_exact<std::string>()) return *v;
  c.fail(where + key, "expected a string");
}

/// The finite number `n` (an integer or a float); `key` names it in the error.
inline double number_of(const Source& c, const toml::node& n, const std::string& key) {
  if (auto v = n.value_exact<double>()) {
    if (!std::isfinite(*v)) c.fail(key, "expected a finite number");
    return *v;
  }
  if (auto v = n.value_exact<int64_t>()) return double(*v);
  c.fail(key, "expected a number");
}

/// The number at `key`, `def` when absent.
inline double num(const Source& c, const toml::table& t, const std::string& key, const std::string& where, double def) {
  const auto* n = t.get(key);
  return n ? number_of(c, *n, where + key) : def;
}

/// The array of numbers `n`.
inline std::vector<double> numbers(const Source& c, const toml::node& n, const std::string& key) {
  const auto* a = n.as_array();
  if (!a) c.fail(key, "expected an array of numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < a->size(); ++i) v.push_back(number_of(c, *a->get(i), key + "[" + std::to_string(i) + "]"));
  return v;
}

/// The colour [r, g, b] `n`, each in [0, 1].
inline std::array<float, 3> colour(const Source& c, const toml::node& n, const std::string& key) {
  const auto v = numbers(c, n, key);
  if (v.size() != 3) c.fail(key, "expected [r, g, b] with three numbers in [0, 1]");
  for (double x : v)
    if (!(x >= 0 && x <= 1)) c.fail(key, "expected [r, g, b] with three numbers in [0, 1]");
  return {float(v[0]), float(v[1]), float(v[2])};
}

}  // namespace panoptes::toml_keys
