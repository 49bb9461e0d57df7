#include "harness/recording/format/gzip.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <zlib.h>

namespace omniloc::harness {

std::string gzip_compress(std::string_view bytes) {
  z_stream z{};
  // windowBits 15 + 16: a gzip header and trailer instead of zlib's.
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw std::runtime_error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, static_cast<uLong>(bytes.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
  return out;
}

std::string gzip_decompress(std::string_view gz, std::size_t max_bytes) {
  z_stream z{};
  if (inflateInit2(&z, 15 + 16) != Z_OK) throw std::runtime_error("zlib: inflateInit2 failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(gz.data()));
  z.avail_in = static_cast<uInt>(gz.size());
  std::string out;
  char buf[1 << 16];
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    z.next_out = reinterpret_cast<Bytef*>(buf);
    z.avail_out = sizeof buf;
    rc = inflate(&z, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&z);
      throw std::runtime_error(rc == Z_BUF_ERROR ? "the gzip stream is cut short" : "not a valid gzip stream");
    }
    out.append(buf, sizeof buf - z.avail_out);
    if (out.size() > max_bytes) {
      inflateEnd(&z);
      throw std::runtime_error("more than " + std::to_string(max_bytes) + " bytes uncompressed");
    }
    if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
      inflateEnd(&z);
      throw std::runtime_error("the gzip stream is cut short");
    }
  }
  const bool trailing = z.avail_in != 0;
  inflateEnd(&z);
  if (trailing) throw std::runtime_error("bytes after the end of the gzip stream");
  return out;
}

struct GzipFileReader::State {
  std::FILE* f = nullptr;
  z_stream z{};
  std::vector<unsigned char> in = std::vector<unsigned char>(1 << 18);
  bool ended = false;
  ~State() {
    inflateEnd(&z);
    if (f) std::fclose(f);
  }
};

GzipFileReader::GzipFileReader(const std::string& path) : s_(std::make_unique<State>()) {
  s_->f = std::fopen(path.c_str(), "rb");
  if (!s_->f) throw std::runtime_error(std::string("cannot open: ") + std::strerror(errno));
  if (inflateInit2(&s_->z, 15 + 16) != Z_OK) throw std::runtime_error("zlib: inflateInit2 failed");
}

GzipFileReader::~GzipFileReader() = default;

std::size_t GzipFileReader::read(char* out, std::size_t n) {
  State& s = *s_;
  if (s.ended || n == 0) return 0;
  s.z.next_out = reinterpret_cast<Bytef*>(out);
  s.z.avail_out = static_cast<uInt>(n);
  while (s.z.avail_out == n) {
    if (s.z.avail_in == 0) {
      const std::size_t got = std::fread(s.in.data(), 1, s.in.size(), s.f);
      if (got == 0) throw std::runtime_error(std::ferror(s.f) ? "cannot read the gzip stream" : "the gzip stream is cut short");
      s.z.next_in = s.in.data();
      s.z.avail_in = static_cast<uInt>(got);
    }
    const int rc = inflate(&s.z, Z_NO_FLUSH);
    if (rc == Z_STREAM_END) {
      s.ended = true;
      // Nothing may follow the stream: neither in the buffer nor in the file.
      if (s.z.avail_in != 0 || std::fgetc(s.f) != EOF) throw std::runtime_error("bytes after the end of the gzip stream");
      break;
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) throw std::runtime_error("not a valid gzip stream");
  }
  return n - s.z.avail_out;
}

}  // namespace omniloc::harness
