#pragma once
// Framing of olp/1 (docs/protocol.md, section 3): one JSON object per line, UTF-8, ended by '\n';
// a message may announce binary parts ("binary": [{"name", "dtype", "shape", "bytes"}]) whose raw
// bytes follow its newline in order. This file holds the byte-level part only: encoding a message,
// and an incremental reader that is fed whatever bytes arrived from a pipe and hands out whole
// messages. It does no I/O, so the libFuzzer harness drives it directly.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/json_parse.hpp"

namespace omniloc::external {

inline constexpr const char* kProtocol = "olp/1";
/// A line (one message's JSON text) may be at most this long (docs/protocol.md: 16 MiB).
inline constexpr std::size_t kMaxLineBytes = 16u << 20;
/// The binary parts of one message may be at most this many bytes together (64 MiB).
inline constexpr std::size_t kMaxBinaryBytes = 64u << 20;

/// One raw part announced by a message.
struct BinaryPart {
  std::string name;
  std::string dtype;                 ///< "uint8" in olp/1
  std::vector<std::int64_t> shape;
  std::string_view data;             ///< the bytes (points into the caller's buffer for encoding)
};

/// A protocol violation in the byte stream or a message's form: the run fails with `what()`.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The bytes of one message: `header` as one JSON line (its "binary" field is set from `parts`
/// when there are any), then the parts' bytes. Doubles are written with 17 significant digits.
std::string encode_message(Json header, const std::vector<BinaryPart>& parts = {});

/// A message as received: the parsed header and the bytes of its parts, in order.
struct Message {
  Json header;
  std::vector<std::string> parts;  ///< one byte string per entry of header["binary"]
  std::string type() const;        ///< header["type"] ("" when missing or not a string)
};

/// Incremental reader: feed() appends bytes as they arrive, next() returns a whole message when
/// one is complete. Throws ProtocolError on a line that is not a JSON object (or not UTF-8, or too
/// long) and on a malformed "binary" announcement; after a throw the reader is unusable.
class MessageReader {
 public:
  void feed(std::string_view bytes);
  std::optional<Message> next();
  /// Bytes received and not yet part of a complete message (a partial line or part).
  std::size_t pending() const { return buf_.size() - pos_; }

 private:
  std::string buf_;
  std::size_t pos_ = 0;
  std::optional<Message> partial_;       // header read, parts still arriving
  std::vector<std::size_t> part_sizes_;  // of partial_
};

/// The first `n` bytes of `s` with control characters escaped, for error messages.
std::string printable_prefix(std::string_view s, std::size_t n = 200);

}  // namespace omniloc::external
