#include "core/interrupt.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

namespace omniloc::interrupt {

namespace {

constexpr int kMaxGroups = 256;
constexpr int kMaxFolders = 256;
constexpr std::size_t kPathMax = 4096;

std::atomic<int> g_groups[kMaxGroups];
// A folder slot: 0 free, 1 being written, 2 holds a path the handler may read.
std::atomic<int> g_folder_state[kMaxFolders];
char g_folders[kMaxFolders][kPathMax];
struct sigaction g_previous[65];
std::once_flag g_installed;

void sleep_ms(long ms) {
  timespec ts{ms / 1000, (ms % 1000) * 1000000L};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

void say(const char* s) {
  std::size_t n = std::strlen(s);
  while (n > 0) {
    const ssize_t w = ::write(STDERR_FILENO, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<std::size_t>(w);
  }
}

// End every client group: TERM, up to 2 s for them to go, then KILL.
void end_groups() {
  bool any = false;
  for (auto& g : g_groups)
    if (const int pid = g.load(); pid > 0) {
      kill(-pid, SIGTERM);
      any = true;
    }
  for (int waited = 0; any && waited < 2000; waited += 20) {
    bool alive = false;
    for (auto& g : g_groups)
      if (const int pid = g.load(); pid > 0) {
        siginfo_t info{};
        // WNOWAIT: leave the zombie, so its pid (the group id) cannot be reused before the KILL below.
        if (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == 0) alive = true;
      }
    if (!alive) break;
    sleep_ms(20);
  }
  for (auto& g : g_groups)
    if (const int pid = g.load(); pid > 0) kill(-pid, SIGKILL);
}

// Recursive removal below the open directory `dfd` (closed here); depth-limited. Entries are removed
// while the listing is read, so the listing is read again from the start until a pass removes nothing.
bool remove_below(int dfd, int depth) {
  struct Entry {  // struct linux_dirent64
    unsigned long long ino;
    long long off;
    unsigned short reclen;
    unsigned char type;
    char name[1];
  };
  bool ok = true;
  alignas(8) char buf[4096];
  for (int pass = 0; pass < 1000; ++pass) {
    bool removed = false;
    for (;;) {
      const long n = syscall(SYS_getdents64, dfd, buf, sizeof buf);
      if (n < 0) ok = false;
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        const auto* e = reinterpret_cast<const Entry*>(buf + off);
        off += e->reclen;
        const char* name = e->name;
        if (name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0))) continue;
        if (unlinkat(dfd, name, 0) == 0) {
          removed = true;
          continue;
        }
        if (errno != EISDIR && errno != EPERM) continue;
        const int sub = depth < 32 ? openat(dfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC) : -1;
        if (sub < 0) continue;
        remove_below(sub, depth + 1);
        if (unlinkat(dfd, name, AT_REMOVEDIR) == 0) removed = true;
      }
    }
    if (!removed) break;
    lseek(dfd, 0, SEEK_SET);
  }
  close(dfd);
  return ok;
}

void remove_folders() {
  bool any = false, all = true;
  for (int i = 0; i < kMaxFolders; ++i)
    if (g_folder_state[i].load() == 2) {
      any = true;
      all = remove_tree(g_folders[i]) && all;
    }
  if (any) say(all ? "; the unfinished run's staging folder was removed, no results written" : "; some of the unfinished run's staging files could not be removed (the next run there clears them)");
}

void on_signal(int sig) {
  const int saved_errno = errno;
  say(sig == SIGINT ? "omniloc: interrupted (SIGINT)" : sig == SIGTERM ? "omniloc: terminated (SIGTERM)" : "omniloc: hung up (SIGHUP)");
  end_groups();
  remove_folders();
  say("\n");
  const struct sigaction& prev = g_previous[sig];
  if (prev.sa_handler == SIG_IGN) {
    errno = saved_errno;
    return;
  }
  if (!(prev.sa_flags & SA_SIGINFO) && prev.sa_handler != SIG_DFL) {
    prev.sa_handler(sig);
    errno = saved_errno;
    return;
  }
  // Die of the signal itself, so the parent sees "killed by SIGINT" (a shell prints 130).
  signal(sig, SIG_DFL);
  raise(sig);
}

}  // namespace

bool remove_tree(const char* path) {
  if (unlink(path) == 0) return true;
  if (errno == ENOENT) return true;
  const int fd = open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return errno == ENOENT;
  remove_below(fd, 0);
  return rmdir(path) == 0 || errno == ENOENT;
}

void install() {
  std::call_once(g_installed, [] {
    // A client that died closes its stdin pipe: writing then must fail with EPIPE, not kill omniloc.
    signal(SIGPIPE, SIG_IGN);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction prev{};
      sigaction(sig, nullptr, &prev);
      g_previous[sig] = prev;
      if (prev.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
      struct sigaction sa{};
      sa.sa_handler = on_signal;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = 0;
      sigaction(sig, &sa, nullptr);
    }
  });
}

void watch_group(int pid) {
  install();
  for (auto& g : g_groups) {
    int expected = 0;
    if (g.compare_exchange_strong(expected, pid)) return;
  }
}

void unwatch_group(int pid) {
  for (auto& g : g_groups) {
    int expected = pid;
    if (g.compare_exchange_strong(expected, 0)) return;
  }
}

int watch_folder(const char* path) {
  install();
  const std::size_t n = std::strlen(path);
  if (n == 0 || n >= kPathMax) return -1;
  for (int i = 0; i < kMaxFolders; ++i) {
    int expected = 0;
    if (g_folder_state[i].compare_exchange_strong(expected, 1)) {
      std::memcpy(g_folders[i], path, n + 1);
      g_folder_state[i].store(2);
      return i;
    }
  }
  return -1;
}

void unwatch_folder(int slot) {
  if (slot >= 0 && slot < kMaxFolders) g_folder_state[slot].store(0);
}

}  // namespace omniloc::interrupt
