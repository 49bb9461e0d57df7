#include "external/sha256.hpp"

#include <fstream>
#include <memory>
#include <vector>

#include <openssl/evp.h>

#include "core/error.hpp"

namespace omniloc::external {

Sha256::Sha256() : ctx_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
  if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1) throw RuntimeFailure("OpenSSL: cannot start a SHA-256 digest");
}

void Sha256::add(const char* data, std::size_t n) { EVP_DigestUpdate(ctx_.get(), data, n); }

std::string Sha256::hex() {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestFinal_ex(ctx_.get(), md, &len);
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) {
    out += digits[md[i] >> 4];
    out += digits[md[i] & 15];
  }
  return out;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 d;
  d.add(bytes.data(), bytes.size());
  return d.hex();
}

std::string sha256_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw RuntimeFailure("cannot read " + path + " to hash it");
  Sha256 d;
  std::vector<char> buf(1 << 16);
  while (f) {
    f.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (f.gcount() > 0) d.add(buf.data(), static_cast<std::size_t>(f.gcount()));
  }
  if (f.bad()) throw RuntimeFailure("cannot read " + path + " to hash it");
  return d.hex();
}

}  // namespace omniloc::external
