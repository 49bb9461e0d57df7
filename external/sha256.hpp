#pragma once
// SHA-256 through OpenSSL's libcrypto: what identifies an external client's files and a sweep's
// specification in the records (summary.json, slurm/submission.json).
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace omniloc::external {

/// SHA-256 of bytes given piece by piece (a recording's frames as they are decompressed).
class Sha256 {
 public:
  Sha256();
  void add(const char* data, std::size_t n);
  /// Lower-case hex digest; call once, after the last add().
  std::string hex();

 private:
  std::unique_ptr<evp_md_ctx_st, void (*)(evp_md_ctx_st*)> ctx_;
};

/// Lower-case hex SHA-256 of `bytes`.
std::string sha256_hex(std::string_view bytes);
/// Lower-case hex SHA-256 of a file's bytes; throws RuntimeFailure when it cannot be read.
std::string sha256_file(const std::string& path);

}  // namespace omniloc::external
