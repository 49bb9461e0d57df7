#include "harness/cache/shared_library.hpp"

#include <elf.h>
#include <sys/stat.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace omniloc {

std::string find_shared_library(const std::string& soname) {
  std::vector<std::string> dirs;
  if (const char* ld = std::getenv("LD_LIBRARY_PATH"))
    for (std::string s = ld; !s.empty();) {
      const auto c = s.find(':');
      if (c != 0) dirs.push_back(s.substr(0, c));
      s = c == std::string::npos ? "" : s.substr(c + 1);
    }
  for (const char* d : {"/usr/lib/x86_64-linux-gnu", "/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/lib/aarch64-linux-gnu",
                        "/usr/local/lib", "/usr/lib", "/lib"})
    dirs.push_back(d);
  for (const auto& d : dirs) {
    std::error_code ec;
    const fs::path p = fs::canonical(fs::path(d) / soname, ec);
    if (!ec && fs::is_regular_file(p, ec)) return p.string();
  }
  return "";
}

namespace {

// Reads bytes of a file at given offsets; every read is checked against the file's size.
class FileBytes {
 public:
  explicit FileBytes(const std::string& path) : in_(path, std::ios::binary) {
    std::error_code ec;
    size_ = in_ ? fs::file_size(path, ec) : 0;
    if (ec) size_ = 0;
  }
  bool read(std::uint64_t off, void* dst, std::uint64_t n) {
    if (off > size_ || size_ - off < n) return false;
    in_.seekg(static_cast<std::streamoff>(off));
    return static_cast<bool>(in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n)));
  }
  template <class T>
  bool read(std::uint64_t off, T& out) {
    return read(off, &out, sizeof(T));
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

}  // namespace

std::vector<std::string> elf_needed(const std::string& path) {
  // Only the ELF header, the program headers, the dynamic section and the string table are read.
  FileBytes f(path);
  Elf64_Ehdr eh{};
  if (!f.read(0, eh) || std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64 ||
      eh.e_ident[EI_DATA] != ELFDATA2LSB || eh.e_phentsize != sizeof(Elf64_Phdr))
    return {};
  std::vector<Elf64_Phdr> loads;
  Elf64_Phdr dyn{};
  bool has_dyn = false;
  for (std::uint64_t i = 0; i < eh.e_phnum; ++i) {
    Elf64_Phdr ph{};
    if (!f.read(eh.e_phoff + i * sizeof(Elf64_Phdr), ph)) return {};
    if (ph.p_type == PT_LOAD) loads.push_back(ph);
    if (ph.p_type == PT_DYNAMIC) dyn = ph, has_dyn = true;
  }
  if (!has_dyn) return {};
  std::vector<std::uint64_t> names;
  std::uint64_t strtab = 0, strsz = 0;
  for (std::uint64_t k = 0; k < dyn.p_filesz / sizeof(Elf64_Dyn); ++k) {
    Elf64_Dyn d{};
    if (!f.read(dyn.p_offset + k * sizeof(Elf64_Dyn), d) || d.d_tag == DT_NULL) break;
    if (d.d_tag == DT_NEEDED) names.push_back(d.d_un.d_val);
    if (d.d_tag == DT_STRTAB) strtab = d.d_un.d_ptr;
    if (d.d_tag == DT_STRSZ) strsz = d.d_un.d_val;
  }
  // DT_STRTAB is an address in memory; the PT_LOAD segment that holds it says where it is in the file.
  std::uint64_t str_off = 0;
  bool found = false;
  for (const auto& l : loads)
    if (strtab >= l.p_vaddr && strtab - l.p_vaddr < l.p_filesz) {
      str_off = l.p_offset + (strtab - l.p_vaddr);
      found = true;
      break;
    }
  if (names.empty() || !found || strsz == 0 || strsz > (64u << 20)) return {};
  std::string table(strsz, '\0');
  if (!f.read(str_off, table.data(), strsz)) return {};
  std::vector<std::string> out;
  for (const std::uint64_t n : names) {
    if (n >= strsz) return {};
    const auto end = table.find('\0', n);
    if (end == std::string::npos) return {};  // not terminated inside the table
    out.push_back(table.substr(n, end - n));
  }
  return out;
}

std::string file_identity(const std::string& path) {
  struct stat st {};
  if (path.empty() || ::stat(path.c_str(), &st) != 0) return "none";
  return path + " " + std::to_string(st.st_size) + " " + std::to_string(st.st_mtime);
}

}  // namespace omniloc
