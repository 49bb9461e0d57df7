#include "external/olp_framing.hpp"

#include <limits>

namespace omniloc::external {

std::string encode_message(Json header, const std::vector<BinaryPart>& parts) {
  if (!parts.empty()) {
    Json b = Json::array();
    for (const auto& p : parts)
      b.push_back({{"name", p.name}, {"dtype", p.dtype}, {"shape", p.shape}, {"bytes", p.data.size()}});
    header["binary"] = std::move(b);
  }
  // nlohmann writes doubles with max_digits10 (17) significant digits: they read back exactly.
  // error_handler replace: a non-UTF-8 string from our side (never expected) cannot make invalid JSON.
  std::string out = header.dump(-1, ' ', false, Json::error_handler_t::replace);
  out += '\n';
  std::size_t total = out.size();
  for (const auto& p : parts) total += p.data.size();
  out.reserve(total);
  for (const auto& p : parts) out.append(p.data);
  return out;
}

std::string Message::type() const {
  const auto it = header.find("type");
  return it != header.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string printable_prefix(std::string_view s, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else out += static_cast<char>(c);
  }
  if (s.size() > n) out += "...";
  return out;
}

namespace {

// The sizes of the parts `header` announces; throws ProtocolError on a malformed announcement.
std::vector<std::size_t> announced_parts(const Json& header) {
  std::vector<std::size_t> sizes;
  const auto it = header.find("binary");
  if (it == header.end()) return sizes;
  if (!it->is_array()) throw ProtocolError("/binary: expected an array of {name, dtype, shape, bytes}");
  std::size_t total = 0;
  for (std::size_t i = 0; i < it->size(); ++i) {
    const Json& p = (*it)[i];
    const std::string at = "/binary/" + std::to_string(i);
    if (!p.is_object()) throw ProtocolError(at + ": expected an object {name, dtype, shape, bytes}");
    const auto name = p.find("name"), dtype = p.find("dtype"), shape = p.find("shape"), bytes = p.find("bytes");
    if (name == p.end() || !name->is_string()) throw ProtocolError(at + "/name: expected a string");
    if (dtype == p.end() || !dtype->is_string() || *dtype != "uint8") throw ProtocolError(at + "/dtype: expected \"uint8\"");
    if (shape == p.end() || !shape->is_array() || shape->empty()) throw ProtocolError(at + "/shape: expected a non-empty array of sizes");
    std::size_t product = 1;
    for (const Json& s : *shape) {
      if (!s.is_number_unsigned() || s.get<std::uint64_t>() > kMaxBinaryBytes)
        throw ProtocolError(at + "/shape: expected sizes in [0, " + std::to_string(kMaxBinaryBytes) + "]");
      product *= s.get<std::size_t>();
      if (product > kMaxBinaryBytes) throw ProtocolError(at + "/shape: more than " + std::to_string(kMaxBinaryBytes) + " bytes");
    }
    if (bytes == p.end() || !bytes->is_number_unsigned() || bytes->get<std::uint64_t>() != product)
      throw ProtocolError(at + "/bytes: expected the product of shape (" + std::to_string(product) + ")");
    total += product;
    if (total > kMaxBinaryBytes) throw ProtocolError("/binary: more than " + std::to_string(kMaxBinaryBytes) + " bytes in one message");
    sizes.push_back(product);
  }
  return sizes;
}

}  // namespace

void MessageReader::feed(std::string_view bytes) {
  // Drop what was consumed before growing, so a long session keeps a buffer of one message.
  if (pos_ > 0 && pos_ >= buf_.size() / 2) {
    buf_.erase(0, pos_);
    pos_ = 0;
  }
  buf_.append(bytes);
}

std::optional<Message> MessageReader::next() {
  if (!partial_) {
    const std::size_t nl = buf_.find('\n', pos_);
    if (nl == std::string::npos) {
      if (buf_.size() - pos_ > kMaxLineBytes)
        throw ProtocolError("a line longer than " + std::to_string(kMaxLineBytes) + " bytes: " + printable_prefix(std::string_view(buf_).substr(pos_)));
      return std::nullopt;
    }
    std::string_view line(buf_.data() + pos_, nl - pos_);
    if (line.size() > kMaxLineBytes) throw ProtocolError("a line longer than " + std::to_string(kMaxLineBytes) + " bytes");
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    Json header;
    try {
      header = parse_json_strict(line, "message");
    } catch (const std::exception& e) {
      // NaN and Infinity are what a client most often writes by accident (Python's json.dumps does
      // by default): say so, rather than leave the parser's offset to be puzzled over.
      const bool non_finite = line.find("NaN") != std::string_view::npos || line.find("Infinity") != std::string_view::npos;
      throw ProtocolError("not a JSON object: " + printable_prefix(line) + " (" + e.what() + ")" +
                          (non_finite ? "; NaN and Infinity are not JSON numbers: send finite numbers (docs/protocol.md section 3)" : ""));
    }
    if (!header.is_object()) throw ProtocolError("not a JSON object: " + printable_prefix(line));
    part_sizes_ = announced_parts(header);
    pos_ = nl + 1;
    partial_ = Message{std::move(header), {}};
  }
  // Parts: wait until every byte of all of them is here, then cut them out in order.
  std::size_t need = 0;
  for (std::size_t s : part_sizes_) need += s;
  if (buf_.size() - pos_ < need) return std::nullopt;
  for (std::size_t s : part_sizes_) {
    partial_->parts.emplace_back(buf_, pos_, s);
    pos_ += s;
  }
  part_sizes_.clear();
  std::optional<Message> out = std::move(partial_);
  partial_.reset();
  return out;
}

}  // namespace omniloc::external
