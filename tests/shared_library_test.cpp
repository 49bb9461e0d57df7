// Reading which libraries a shared library links, without loading it (harness/cache/shared_library.hpp):
// the world cache's key names the OSMesa library and what it links (LLVM among them), so a Mesa or
// LLVM update misses the cache. Checked against binutils' readelf where it is installed, and on
// damaged files, which must give an empty list, never a crash or a read past the file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "harness/cache/shared_library.hpp"

using namespace omniloc;
namespace fs = std::filesystem;

namespace {

std::string self_exe() { return fs::canonical("/proc/self/exe").string(); }

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("shared_library_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

// readelf's "(NEEDED)  Shared library: [name]" lines, in order; empty when readelf is missing.
std::vector<std::string> readelf_needed(const std::string& path) {
  std::vector<std::string> out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(::popen(("readelf -d '" + path + "' 2>/dev/null").c_str(), "r"), ::pclose);
  if (!p) return out;
  char line[4096];
  while (std::fgets(line, sizeof line, p.get())) {
    const std::string l = line;
    if (l.find("(NEEDED)") == std::string::npos) continue;
    const auto a = l.find('['), b = l.rfind(']');
    if (a != std::string::npos && b != std::string::npos && b > a) out.push_back(l.substr(a + 1, b - a - 1));
  }
  return out;
}

}  // namespace

TEST(ElfNeeded, NamesWhatTheTestProgramLinksAsReadelfDoes) {
  const auto needed = elf_needed(self_exe());
  ASSERT_FALSE(needed.empty());
  EXPECT_NE(std::find(needed.begin(), needed.end(), "libc.so.6"), needed.end());
  const auto reference = readelf_needed(self_exe());
  if (reference.empty()) GTEST_SKIP() << "readelf (binutils) not installed: compared with libc.so.6 only";
  EXPECT_EQ(needed, reference);
}

TEST(ElfNeeded, OsmesaLinksLlvm) {
  const std::string osmesa = find_shared_library("libOSMesa.so.8");
  if (osmesa.empty()) GTEST_SKIP() << "libOSMesa.so.8 not installed";
  const auto needed = elf_needed(osmesa);
  bool llvm = false;
  for (const auto& n : needed) llvm = llvm || n.rfind("libLLVM", 0) == 0;
  EXPECT_TRUE(llvm) << "Debian's Mesa draws with llvmpipe, which links LLVM";
  const auto reference = readelf_needed(osmesa);
  if (!reference.empty()) {
    EXPECT_EQ(needed, reference);
  }
}

TEST(ElfNeeded, DamagedOrOtherFilesGiveNothing) {
  const fs::path d = temp_dir();
  const std::string whole = slurp(self_exe());
  ASSERT_GT(whole.size(), 4096u);
  EXPECT_TRUE(elf_needed((d / "missing").string()).empty());
  // Cut anywhere before the dynamic section's strings: an empty list, never a read past the end.
  for (const std::size_t n : {std::size_t{0}, std::size_t{4}, std::size_t{63}, std::size_t{64}, std::size_t{200}, std::size_t{1000}}) {
    std::ofstream(d / "cut", std::ios::binary | std::ios::trunc).write(whole.data(), static_cast<std::streamsize>(n));
    EXPECT_TRUE(elf_needed((d / "cut").string()).empty()) << n << " bytes";
  }
  std::ofstream(d / "text", std::ios::trunc) << "not an ELF file\n";
  EXPECT_TRUE(elf_needed((d / "text").string()).empty());
  // A 32-bit class byte: not read as a 64-bit file.
  std::string other = whole;
  other[4] = 1;  // EI_CLASS = ELFCLASS32
  std::ofstream(d / "class32", std::ios::binary | std::ios::trunc) << other;
  EXPECT_TRUE(elf_needed((d / "class32").string()).empty());
  // Program headers said to lie beyond the file.
  std::string far = whole;
  for (int i = 0; i < 8; ++i) far[32 + i] = '\x7f';  // e_phoff
  std::ofstream(d / "far", std::ios::binary | std::ios::trunc) << far;
  EXPECT_TRUE(elf_needed((d / "far").string()).empty());
  fs::remove_all(d);
}

TEST(FindSharedLibrary, LdLibraryPathFirstThenTheSystem) {
  EXPECT_FALSE(find_shared_library("libc.so.6").empty());
  EXPECT_EQ(find_shared_library("libno-such-library-here.so.1"), "");
  const fs::path d = temp_dir();
  std::ofstream(d / "libc.so.6") << "a stand-in";
  const char* old = std::getenv("LD_LIBRARY_PATH");
  const std::string saved = old ? old : "";
  ::setenv("LD_LIBRARY_PATH", (":" + d.string()).c_str(), 1);  // an empty entry is skipped
  EXPECT_EQ(find_shared_library("libc.so.6"), fs::canonical(d / "libc.so.6").string());
  if (old) ::setenv("LD_LIBRARY_PATH", saved.c_str(), 1);
  else ::unsetenv("LD_LIBRARY_PATH");
  fs::remove_all(d);
}

TEST(FileIdentity, ChangesWithTheFile) {
  const fs::path d = temp_dir();
  const std::string p = (d / "lib.so").string();
  std::ofstream(p) << "one";
  const std::string a = file_identity(p);
  EXPECT_EQ(a.rfind(p + " 3 ", 0), 0u) << a;
  std::ofstream(p, std::ios::trunc) << "three";
  EXPECT_NE(file_identity(p), a);
  EXPECT_EQ(file_identity((d / "none").string()), "none");
  EXPECT_EQ(file_identity(""), "none");
  fs::remove_all(d);
}
