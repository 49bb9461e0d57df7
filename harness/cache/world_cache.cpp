#include "harness/cache/world_cache.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <opencv2/core/version.hpp>

#include "core/atomic_file.hpp"
#include "core/cache_root.hpp"
#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "external/sha256.hpp"
#include "harness/bound_prepare.hpp"
#include "harness/frame_source.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/recording/recording_writer.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/run_directory.hpp"
#include "harness/cache/shared_library.hpp"
#include "omniloc_world_fingerprint.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {

constexpr const char* kManifest = "entry.json";
constexpr const char* kManifestFormat = "omniloc-world-cache/1";
constexpr const char* kLastUsed = "last_used";
// 20 GiB: about 10,000 minutes of recorded worlds without images (1.9 MB a minute), a few thousand
// sweep runs' worlds; images take 915 MiB a minute, so a cache of image worlds fills it in 22 minutes.
constexpr std::uint64_t kDefaultMaxBytes = 20ULL << 30;

// The OSMesa library sim/render/gl_context.cpp loads and every library it links (LLVM, whose code
// generator llvmpipe draws with, glapi, libc, ...), each by path, size and time: a Mesa or LLVM update
// may draw other pixels, so it must miss the cache. Libraries those link in turn are not followed.
// Computed once a process: the files do not change under a running program.
const std::string& osmesa_identity() {
  static const std::string id = [] {
    const std::string osmesa = find_shared_library("libOSMesa.so.8");
    if (osmesa.empty()) return std::string("none");
    std::string s = file_identity(osmesa);
    for (const auto& needed : elf_needed(osmesa)) s += "; " + needed + " " + file_identity(find_shared_library(needed));
    return s;
  }();
  return id;
}

// Whether a path of the cache exists; a path the system cannot look at (a name too long, a loop of
// links) is not there, and writing it then says why (IoError), which never costs a run.
bool there(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

std::uint64_t folder_bytes(const fs::path& dir) {
  std::uint64_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) n += it->file_size(ec);
  return n;
}

std::time_t mtime_of(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 ? st.st_mtime : 0;
}

void touch(const fs::path& p) {
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd >= 0) {
    ::futimens(fd, nullptr);
    ::close(fd);
  }
}

void flock_retry(int fd, int op) {
  while (::flock(fd, op) != 0)
    if (errno != EINTR) throw RuntimeFailure(std::string("world cache: cannot lock: ") + std::strerror(errno));
}

// The images of an entry: how many, how many bytes (they are counted and sized, not hashed: a
// damaged PNG fails to decode when it is read).
void count_images(const fs::path& dir, long long& images, std::uint64_t& image_bytes) {
  images = 0;
  image_bytes = 0;
  std::error_code ec;
  for (const auto& i : fs::directory_iterator(dir / "images", ec)) {
    ++images;
    image_bytes += i.file_size(ec);
  }
}

// The manifest's files: every regular file of the recording folder, sized and hashed.
Json manifest_files(const fs::path& dir) {
  Json files = Json::object();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name == kManifest || name == kLastUsed || !e.is_regular_file(ec)) continue;
    files[name] = {{"bytes", e.file_size(ec)}, {"sha256", external::sha256_file(e.path().string())}};
  }
  return files;
}

}  // namespace

std::uint64_t parse_byte_size(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  std::string unit = used == 0 ? "?" : text.substr(used);
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  if (!unit.empty() && (unit.back() == 'i')) unit.pop_back();
  double mult = 0;
  if (unit.empty()) mult = 1;
  else if (unit == "K" || unit == "k") mult = 1024.0;
  else if (unit == "M" || unit == "m") mult = 1024.0 * 1024;
  else if (unit == "G" || unit == "g") mult = 1024.0 * 1024 * 1024;
  else if (unit == "T" || unit == "t") mult = 1024.0 * 1024 * 1024 * 1024;
  if (used == 0 || mult == 0 || !(v >= 0) || v * mult > 9.0e18)
    throw ConfigError(what, "\"" + text + "\"", "a size in bytes, or with K, M, G or T (e.g. 500M, 20G)");
  return static_cast<std::uint64_t>(v * mult);
}

std::string format_bytes(std::uint64_t b) {
  char s[64];
  if (b >= (1ULL << 30)) std::snprintf(s, sizeof s, "%.2f GiB", static_cast<double>(b) / (1ULL << 30));
  else if (b >= (1ULL << 20)) std::snprintf(s, sizeof s, "%.1f MiB", static_cast<double>(b) / (1ULL << 20));
  else if (b >= 1024) std::snprintf(s, sizeof s, "%.1f KiB", static_cast<double>(b) / 1024);
  else std::snprintf(s, sizeof s, "%llu B", static_cast<unsigned long long>(b));
  return s;
}

WorldCacheOptions world_cache_from_env() {
  WorldCacheOptions o;
  o.dir = cache::dir("worlds");
  const char* max = std::getenv("OMNILOC_CACHE_MAX_SIZE");
  o.max_bytes = max ? parse_byte_size(max, "OMNILOC_CACHE_MAX_SIZE") : kDefaultMaxBytes;
  return o;
}

std::string world_cache_ineligible(const Scenario& sc, const RunOptions& opt) {
  if (sc.localizer.type() != "external" && !localizer_info(sc.localizer).needs_vision) return "a localizer without vision runs live";
  if (!opt.frames_dir.empty()) return "--frames draws the images";
  // The back-end the run really draws with: OMNILOC_GL_BACKEND overrides the file's camera.backend,
  // and only the effective camera block holds the result.
  const Json* cam = sc.effective.contains("camera") ? &sc.effective["camera"] : nullptr;
  const std::string backend = cam && cam->is_object() ? cam->value("backend", std::string("osmesa")) : std::string("osmesa");
  if (backend != "osmesa") return "the " + backend + " renderer's pixels depend on the machine";
  return "";
}

std::string world_key(const Scenario& sc, std::uint64_t seed, bool images) {
  Json world = sc.effective;
  for (const char* k : {"localizer", "name", "description", "seed", "scoring"}) world.erase(k);
  // Files the scenario names (a calibration map, a colour table): their content, wherever they are.
  Json files = Json::object();
  if (world.contains("vision") && world["vision"].is_object())
    for (const char* k : {"calibration", "colour_table"}) {
      const std::string v = world["vision"].value(k, std::string("auto"));
      if (v == "auto" || v == "exact") continue;
      fs::path p = v;
      std::error_code ec;
      if (p.is_relative() && !fs::exists(p, ec) && !sc.source.empty()) p = fs::path(sc.source).parent_path() / v;
      files[k] = fs::is_regular_file(p, ec) ? external::sha256_file(p.string()) : std::string("missing");
    }
  const Json key = {{"cache", kManifestFormat},   {"world", world},
                    {"seed", seed},               {"noise_profile", sc.noise.name},
                    {"field", sc.field.fingerprint()}, {"files", files},
                    {"images", images},           {"code", OMNILOC_WORLD_FINGERPRINT},
                    {"opencv", CV_VERSION},       {"osmesa", osmesa_identity()}};
  return external::sha256_hex(key.dump()).substr(0, 32);
}

WorldLease::~WorldLease() {
  if (fd_ >= 0) ::close(fd_);
}

WorldCache::WorldCache(WorldCacheOptions o) : o_(std::move(o)) {}

std::string WorldCache::entry_dir(const std::string& key) const { return (fs::path(o_.dir) / key).string(); }

int WorldCache::lock(const std::string& key) const {
  try {
    return open_lock(key);
  } catch (const IoError& e) {
    throw WorldCacheUnwritable(e);
  }
}

int WorldCache::open_lock(const std::string& key) const {
  const fs::path locks = fs::path(o_.dir) / ".locks";
  std::error_code ec;
  fs::create_directories(locks, ec);
  if (ec) throw IoError("cannot create folder", locks.string(), ec.message());
  const std::string path = (locks / (key + ".lock")).string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError("cannot create lock", path, errno);
  return fd;
}

std::string WorldCache::damage(const std::string& key) const {
  const fs::path dir = entry_dir(key);
  const fs::path manifest = dir / kManifest;
  if (!there(manifest)) return "no " + std::string(kManifest) + ": its drawing was interrupted";
  Json m;
  try {
    m = read_json_strict(manifest.string(), manifest.string());
  } catch (const std::exception& e) {
    return std::string(kManifest) + " unreadable (" + e.what() + ")";
  }
  if (!m.is_object() || m.value("format", std::string()) != kManifestFormat || !m.contains("files") || !m["files"].is_object())
    return std::string(kManifest) + " is not a manifest of " + kManifestFormat;
  std::error_code ec;
  for (const auto& [name, f] : m["files"].items()) {
    const fs::path p = dir / name;
    if (!fs::is_regular_file(p, ec)) return name + " missing";
    if (!f.is_object() || fs::file_size(p, ec) != f.value("bytes", std::uint64_t{0}))
      return name + " has " + std::to_string(fs::file_size(p, ec)) + " bytes, the manifest " + f.value("bytes", Json(0)).dump();
    if (external::sha256_file(p.string()) != f.value("sha256", std::string())) return name + " changed (SHA-256)";
  }
  long long images = 0;
  std::uint64_t image_bytes = 0;
  count_images(dir, images, image_bytes);
  if (images != m.value("image_files", 0LL) || image_bytes != m.value("image_bytes", std::uint64_t{0}))
    return "images/ holds " + std::to_string(images) + " files, " + std::to_string(image_bytes) + " bytes; the manifest " +
           m.value("image_files", Json(0)).dump() + ", " + m.value("image_bytes", Json(0)).dump();
  return "";
}

std::optional<WorldLease> WorldCache::find(const std::string& key) {
  if (o_.dir.empty() || !there(entry_dir(key))) return std::nullopt;
  const int fd = lock(key);
  flock_retry(fd, LOCK_SH);
  if (there(entry_dir(key)) && damage(key).empty()) {
    touch(fs::path(entry_dir(key)) / kLastUsed);
    return WorldLease(entry_dir(key), key, false, fd);
  }
  ::close(fd);
  return std::nullopt;
}

WorldLease WorldCache::get(const Scenario& sc, std::uint64_t seed, bool images) {
  const std::string key = world_key(sc, seed, images);
  const fs::path dir = entry_dir(key);
  const int fd = lock(key);
  // flock turns an exclusive lock into a shared one by dropping it first: in between, a prune in
  // another process may take the key and remove the entry. Then the entry is looked up again.
  auto still_there_shared = [&] {
    flock_retry(fd, LOCK_SH);
    return there(dir / kManifest);
  };
  try {
    for (;;) {
      flock_retry(fd, LOCK_SH);
      if (there(dir) && damage(key).empty()) {
        touch(dir / kLastUsed);
        if (o_.log) *o_.log << "  world cache: " << sc.name << ", seed " << seed << " from " << dir.string() << "\n";
        return WorldLease(dir.string(), key, false, fd);
      }
      // Drawing needs the key alone; whoever holds it may be drawing the same world right now.
      flock_retry(fd, LOCK_UN);
      flock_retry(fd, LOCK_EX);
      if (there(dir)) {
        const std::string why = damage(key);
        if (why.empty()) {
          touch(dir / kLastUsed);
          if (!still_there_shared()) continue;
          if (o_.log) *o_.log << "  world cache: " << sc.name << ", seed " << seed << " from " << dir.string() << "\n";
          return WorldLease(dir.string(), key, false, fd);
        }
        // Always said, even by a quiet run: the cache was not what it claimed to be.
        std::cerr << "omniloc: world cache entry " << dir.string() << " is damaged (" << why << "): removed, drawing it again\n";
        std::error_code ec;
        fs::remove_all(dir, ec);
        if (ec) throw IoError("cannot remove the damaged entry", dir.string(), ec.message());
      }
      std::error_code ec;
      fs::create_directories(o_.dir, ec);
      if (ec) throw IoError("cannot create folder", o_.dir, ec.message());
      remove_stale_partials(o_.dir);
      Scenario world = sc;
      world.input.erase("localizer");  // the recording keeps no localizer; every run replays it with its own
      RecordOptions ro;
      ro.seed = seed;
      ro.out_dir = dir.string();
      ro.images = images;
      if (o_.log) *o_.log << "  world cache: drawing " << sc.name << ", seed " << seed << (images ? " with images" : "") << " into " << dir.string() << "\n";
      BoundPreparer bounds(world);  // the world's bounds too: then even its first replay reads them
      ro.on_frame = [&bounds](const FrameData& f) { bounds.add(f); };
      const RecordResult rec = record_scenario(world, ro);
      bounds.finish();
      long long n_images = 0;
      std::uint64_t image_bytes = 0;
      count_images(dir, n_images, image_bytes);
      const Json files = manifest_files(dir);
      const Json manifest = {{"format", kManifestFormat}, {"key", key},           {"scenario", sc.name},
                             {"seed", seed},              {"images", images},     {"frames", rec.frames},
                             {"files", files},            {"image_files", n_images}, {"image_bytes", image_bytes}};
      write_file_atomic((dir / kManifest).string(), manifest.dump(2) + "\n");
      touch(dir / kLastUsed);
      if (!still_there_shared()) continue;
      if (o_.max_bytes > 0) {
        const PruneResult p = prune(std::nullopt, o_.max_bytes);
        if (p.removed > 0 && o_.log)
          *o_.log << "  world cache: evicted " << p.removed << " least recently used entries (" << format_bytes(p.freed) << ") to stay under "
                  << format_bytes(o_.max_bytes) << "\n";
      }
      return WorldLease(dir.string(), key, true, fd);
    }
  } catch (const IoError& e) {
    ::close(fd);
    // Only a failure to write the cache itself is the cache's; it leaves no partial entry (the
    // recording's staging folder is gone already: RunDirectory removes it when not committed).
    if (e.path().rfind(o_.dir + "/", 0) != 0 && e.path() != o_.dir) throw;
    std::error_code ec;
    if (!fs::exists(dir / kManifest, ec)) fs::remove_all(dir, ec);
    throw WorldCacheUnwritable(e);
  } catch (...) {
    ::close(fd);
    throw;
  }
}

std::vector<WorldEntryInfo> WorldCache::list() const {
  std::vector<WorldEntryInfo> out;
  std::error_code ec;
  if (o_.dir.empty() || !fs::is_directory(o_.dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(o_.dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!e.is_directory(ec) || name.empty() || name[0] == '.') continue;
    WorldEntryInfo w;
    w.key = name;
    w.bytes = folder_bytes(e.path());
    w.last_used = mtime_of(e.path() / kLastUsed);
    if (w.last_used == 0) w.last_used = mtime_of(e.path());
    try {
      const Json m = read_json_strict((e.path() / kManifest).string(), name);
      w.scenario = m.value("scenario", std::string());
      w.seed = m.value("seed", std::uint64_t{0});
      w.images = m.value("images", false);
      w.frames = m.value("frames", 0LL);
    } catch (const std::exception&) {
      w.complete = false;
    }
    out.push_back(std::move(w));
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.last_used != b.last_used ? a.last_used > b.last_used : a.key < b.key; });
  return out;
}

std::uint64_t WorldCache::size() const {
  std::uint64_t n = 0;
  for (const auto& e : list()) n += e.bytes;
  return n;
}

PruneResult WorldCache::prune(std::optional<double> older_than_s, std::optional<std::uint64_t> max_bytes) {
  PruneResult r;
  std::vector<WorldEntryInfo> entries = list();
  std::uint64_t total = 0;
  for (const auto& e : entries) total += e.bytes;
  const std::time_t now = std::time(nullptr);
  // Oldest use first.
  std::reverse(entries.begin(), entries.end());
  for (const auto& e : entries) {
    const bool old = older_than_s && static_cast<double>(now - e.last_used) > *older_than_s;
    const bool over = max_bytes && total > *max_bytes;
    if (!old && !over) {
      ++r.kept;
      continue;
    }
    const Removal how = remove(e.key);
    if (how != Removal::kRemoved) {
      r.busy += how == Removal::kBusy ? 1 : 0;
      ++r.kept;
      continue;
    }
    ++r.removed;
    r.freed += e.bytes;
    total -= e.bytes;
  }
  r.left = total;
  return r;
}

WorldCache::Removal WorldCache::remove(const std::string& key) {
  // An entry in use (a run replaying it holds its lock shared) or being drawn is kept.
  const int fd = lock(key);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return Removal::kBusy;
  }
  std::error_code ec;
  fs::remove_all(entry_dir(key), ec);
  ::close(fd);
  return ec ? Removal::kFailed : Removal::kRemoved;
}

RunResult run_with_world_cache(const Scenario& sc, const RunOptions& opt, WorldCache& cache) {
  std::string why = world_cache_ineligible(sc, opt);
  if (why.empty() && cache::unwritable()) why = "it cannot be written";
  if (cache.options().dir.empty() || !why.empty()) {
    if (opt.log && !cache.options().dir.empty()) *opt.log << "  world cache: not used (" << why << ")\n";
    return run_scenario(sc, opt);
  }
  const std::uint64_t seed = opt.seed.value_or(sc.seed);
  RunOptions o = opt;
  o.replay = true;
  std::optional<WorldLease> lease;
  std::unique_ptr<RecordingSource> source;
  std::unique_ptr<LiveSource> live;  // the world drawn as the run goes, when the cache cannot be written
  const auto open = [&](bool images, Json& provenance) -> FrameSource& {
    try {
      if (!lease || lease->key() != world_key(sc, seed, images)) {
        source.reset();
        lease.reset();
        lease.emplace(cache.get(sc, seed, images));
      }
    } catch (const WorldCacheUnwritable& e) {
      // The cache never costs a run: the same frames come from the live world (what --no-cache runs).
      cache::report_unwritable(e.what());
      live = std::make_unique<LiveSource>(sc, seed, true);
      if (const auto dev = live->perception().render_device()) provenance["render"] = dev->to_json();
      return *live;
    }
    source = std::make_unique<RecordingSource>(RecordingHeader::read(lease->dir()));
    if (!source->header().render.is_null()) provenance["render"] = source->header().render;
    provenance["world_cache"] = lease->key();
    return *source;
  };
  if (sc.localizer.type() != "external") {
    Json provenance = Json::object();
    FrameSource& s = open(false, provenance);
    return run_frames(sc, seed, s, o, provenance);
  }
  // An external client: olp/1's hello needs the cameras before the client says (ready) whether it
  // wants images. They come from an entry already there, else from the live world set up for them.
  std::unique_ptr<FrameSource> hello;
  for (const bool images : {false, true})
    if (!lease) try {
        if (auto l = cache.find(world_key(sc, seed, images))) lease.emplace(std::move(*l));
      } catch (const WorldCacheUnwritable&) {
        // No lock can be taken: nothing to find; get() says why when the frames are wanted.
      }
  if (lease) {
    if (opt.log) *opt.log << "  world cache: " << sc.name << ", seed " << seed << " from " << lease->dir() << "\n";
    hello = std::make_unique<RecordingSource>(RecordingHeader::read(lease->dir()));
  }
  else hello = std::make_unique<LiveSource>(sc, seed, true);
  return run_frames_after_hello(sc, seed, *hello,
                                [&](bool images, Json& provenance) -> FrameSource& {
                                  hello.reset();  // the live world's renderer, when it was set up for hello only
                                  return open(images, provenance);
                                },
                                o, Json::object());
}

}  // namespace omniloc::harness
