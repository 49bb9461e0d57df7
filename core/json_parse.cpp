#include "core/json_parse.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

namespace omniloc {

namespace {

// Builds the DOM without recursion: `stack_` holds the open containers. Errors are thrown as
// ConfigError with the pointer of the value being read.
class StrictBuilder : public nlohmann::json_sax<Json> {
 public:
  explicit StrictBuilder(const std::string& source) : source_(source) {}
  Json result;

  bool null() override { return put(Json(nullptr)); }
  bool boolean(bool v) override { return put(Json(v)); }
  bool number_integer(number_integer_t v) override { return put(Json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return put(Json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return put(Json(v)); }
  bool string(string_t& v) override { return put(Json(std::move(v))); }
  bool binary(binary_t&) override { fail("binary data", "JSON text"); }
  bool start_object(std::size_t) override { return open(Json::object()); }
  bool start_array(std::size_t) override { return open(Json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    Frame& f = stack_.back();
    if (f.node->contains(k)) {
      f.key = k;
      f.has_key = true;
      fail("a second \"" + k + "\" in the same object", "each key at most once per object (the later one would silently win)");
    }
    f.key = std::move(k);
    f.has_key = true;
    return true;
  }
  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) override {
    const std::string token = last_token.size() > 40 ? last_token.substr(0, 37) + "..." : last_token;
    if (ex.id == 406)  // out_of_range: a number literal beyond the range of a double
      fail("the number " + token, "a number within +-1.7e308");
    std::string what = ex.what();
    // nlohmann's message starts with "[json.exception.parse_error.101] parse error at line 1, column 2: ".
    if (const auto p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);
    fail("invalid JSON near byte " + std::to_string(position) + " (\"" + token + "\"): " + what, "valid JSON");
  }

 private:
  struct Frame {
    Json* node;
    std::string key;
    bool has_key = false;
  };
  // Path of the value being read, computed only for a message.
  std::string path() const {
    // An open container below the top one is the last element of its parent; the top one is
    // reading its next element (index = size) or the value of its last key.
    std::string p;
    for (std::size_t i = 0; i < stack_.size(); ++i) {
      const Frame& f = stack_[i];
      const bool top = i + 1 == stack_.size();
      if (f.node->is_array()) p = json_child(p, f.node->size() - (top ? 0 : 1));
      else if (f.has_key) p = json_child(p, f.key);
    }
    return p;
  }
  [[noreturn]] void fail(const std::string& value, const std::string& expected) const {
    throw ConfigError(path(), value + " in " + source_, expected);
  }
  // Places `v` where the parser stands; returns a pointer to the stored value.
  Json* place(Json&& v) {
    if (stack_.empty()) {
      result = std::move(v);
      return &result;
    }
    Frame& f = stack_.back();
    if (f.node->is_array()) {
      f.node->push_back(std::move(v));
      return &f.node->back();
    }
    return &((*f.node)[f.key] = std::move(v));
  }
  // After a complete member the object waits for its next key: a later syntax error is reported
  // at the object, not at the member before it.
  void member_done() {
    if (!stack_.empty() && stack_.back().node->is_object()) stack_.back().has_key = false;
  }
  bool put(Json&& v) {
    place(std::move(v));
    member_done();
    return true;
  }
  bool open(Json&& container) {
    if (stack_.size() >= kJsonMaxDepth)
      fail("arrays/objects nested more than " + std::to_string(kJsonMaxDepth) + " levels deep",
           "at most " + std::to_string(kJsonMaxDepth) + " levels of nesting");
    Json* node = place(std::move(container));
    stack_.push_back(Frame{node, {}, false});
    return true;
  }
  bool close() {
    stack_.pop_back();
    member_done();
    return true;
  }

  const std::string& source_;
  std::vector<Frame> stack_;
};

}  // namespace

Json parse_json_strict(std::string_view text, const std::string& source) {
  if (text.size() > kJsonMaxBytes)
    throw ConfigError("", std::to_string(text.size()) + " bytes in " + source, "a JSON text of at most " + std::to_string(kJsonMaxBytes) + " bytes");
  if (const auto nul = text.find('\0'); nul != std::string_view::npos) {
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i < nul; ++i) {
      if (text[i] == '\n') ++line, col = 1;
      else ++col;
    }
    throw ConfigError("", "a NUL byte at line " + std::to_string(line) + ", column " + std::to_string(col) + " of " + source,
                      "a JSON text without NUL bytes");
  }
  StrictBuilder b(source);
  // strict = true: content after the value is an error; exceptions from the builder propagate.
  Json::sax_parse(text.begin(), text.end(), &b, nlohmann::detail::input_format_t::json, true);
  return std::move(b.result);
}

Json read_json_strict(const std::string& path, const std::string& where) {
  require_readable_file(path, where, "a readable JSON file");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && static_cast<std::size_t>(st.st_size) > kJsonMaxBytes)
    throw ConfigError(where, path_value(path, std::to_string(st.st_size) + " bytes"),
                      "a JSON file of at most " + std::to_string(kJsonMaxBytes) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(where, path_value(path, std::strerror(errno)), "a readable JSON file");
  // Read in chunks up to one byte past the limit, so a file growing meanwhile cannot exhaust
  // memory (and a small file does not pay for a 16 MiB buffer).
  std::string text;
  char buf[65536];
  while (text.size() <= kJsonMaxBytes && in) {
    in.read(buf, sizeof buf);
    text.append(buf, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw ConfigError(where, path_value(path, std::string("read error: ") + std::strerror(errno)), "a readable JSON file");
  return parse_json_strict(text, path);
}

}  // namespace omniloc
