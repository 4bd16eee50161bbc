#include "store/bounded_json.hpp"

#include <vector>

#include "core/error.hpp"

namespace panoptes::store {

namespace {

using json = nlohmann::json;

// A SAX handler that checks the bounds and keeps the key path, and hands every event to nlohmann's
// own DOM builder.
class BoundedSax {
 public:
  BoundedSax(json& root, const std::string& source, const JsonLimits& limits, std::string_view kind)
      : dom_(root, true), source_(source), limits_(limits), kind_(kind) {}

  bool null() { return value() && dom_.null(); }
  bool boolean(bool v) { return value() && dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) { return value() && dom_.number_float(v, s); }
  bool string(json::string_t& v) {
    check_string(v, "string");
    return value() && dom_.string(v);
  }
  bool binary(json::binary_t& v) { return value() && dom_.binary(v); }
  bool start_object(std::size_t n) {
    value();
    open(false);
    return dom_.start_object(n);
  }
  bool key(json::string_t& k) {
    check_string(k, "key");
    Level& top = path_.back();
    if (++top.count > limits_.max_elements)
      fail("object has more than " + std::to_string(limits_.max_elements) + " members");
    top.key = k;
    top.has_key = true;
    return dom_.key(k);
  }
  bool end_object() {
    path_.pop_back();
    return dom_.end_object();
  }
  bool start_array(std::size_t n) {
    value();
    open(true);
    return dom_.start_array(n);
  }
  bool end_array() {
    path_.pop_back();
    return dom_.end_array();
  }
  template <class Exception>
  bool parse_error(std::size_t, const std::string&, const Exception& e) {
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." → keep the useful tail.
    std::string what = e.what();
    const auto close = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && close != std::string::npos) what.erase(0, close + 2);
    // The value that failed has not been counted yet: in an array it is the next element.
    if (!path_.empty() && path_.back().array) ++path_.back().count;
    fail(what);
  }

 private:
  struct Level {
    bool array = false;
    bool has_key = false;
    std::size_t count = 0;  // members seen so far
    std::string key;        // objects: the current member's key
  };

  // Called before every value: counts array elements (the index is part of the key path).
  bool value() {
    if (!path_.empty() && path_.back().array && ++path_.back().count > limits_.max_elements)
      fail("array has more than " + std::to_string(limits_.max_elements) + " elements");
    return true;
  }
  void open(bool array) {
    if (path_.size() >= limits_.max_depth)
      fail("nested deeper than " + std::to_string(limits_.max_depth) + " levels; refused");
    path_.push_back({array, false, 0, {}});
  }
  void check_string(const std::string& s, const char* what) {
    if (s.size() > limits_.max_string)
      fail(std::string(what) + " of " + std::to_string(s.size()) + " bytes, longer than the limit of " +
           std::to_string(limits_.max_string));
  }
  std::string key_path() const {
    std::string p;
    for (const Level& l : path_) {
      if (l.array) {
        if (l.count > 0) p += "[" + std::to_string(l.count - 1) + "]";
      } else if (l.has_key) {
        if (!p.empty()) p += '.';
        p += l.key;
      }
    }
    return p.empty() ? "top level" : p;
  }
  [[noreturn]] void fail(const std::string& what) const {  // NOLINT
    throw FileError(source_, "malformed " + std::string(kind_) + " at " + key_path() + ": " + what);
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  const std::string& source_;
  const JsonLimits& limits_;
  std::string_view kind_;
  std::vector<Level> path_;
};

}  // namespace

json parse_bounded_json(std::string_view text, const std::string& source, const JsonLimits& limits,
                        std::string_view kind) {
  json root;
  BoundedSax sax(root, source, limits, kind);
  json::sax_parse(text.begin(), text.end(), &sax, json::input_format_t::json, true, false);
  return root;
}

}  // namespace panoptes::store
