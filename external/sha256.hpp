#pragma once
// SHA-256 through OpenSSL's libcrypto: what identifies an external client's files and a sweep's
// specification in the records (summary.json, slurm/submission.json).
#include <string>
#include <string_view>

namespace omniloc::external {

/// Lower-case hex SHA-256 of `bytes`.
std::string sha256_hex(std::string_view bytes);
/// Lower-case hex SHA-256 of a file's bytes; throws RuntimeFailure when it cannot be read.
std::string sha256_file(const std::string& path);

}  // namespace omniloc::external
