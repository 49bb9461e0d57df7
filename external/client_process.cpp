#include "external/client_process.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/error.hpp"
#include "core/interrupt.hpp"

extern char** environ;

namespace omniloc::external {

namespace {

bool is_executable_file(const std::string& p) {
  struct stat st{};
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(p.c_str(), X_OK) == 0;
}

void sleep_ms(long ms) {
  timespec ts{ms / 1000, (ms % 1000) * 1000000L};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

int ms_until(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1 << 30));
}

void set_nonblocking(int fd) { fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK); }

}  // namespace

std::optional<std::string> resolve_program(const std::string& name, const std::string& cwd) {
  if (name.empty()) return std::nullopt;
  if (name.find('/') != std::string::npos) {
    const std::string p = name[0] == '/' ? name : cwd + "/" + name;
    return is_executable_file(p) ? std::optional<std::string>(p) : std::nullopt;
  }
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) dir = ".";
    std::string p = dir + "/" + name;
    if (p[0] != '/') p = cwd + "/" + p;
    if (is_executable_file(p)) return p;
  }
  return std::nullopt;
}

std::string describe_wait_status(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "stopped (wait status " + std::to_string(status) + ")";
}

ClientProcess::ClientProcess(const ProcessSpec& spec) : stderr_path_(spec.stderr_path) {
  interrupt::install();
  // Everything the child needs is prepared before fork: after it only async-signal-safe calls.
  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) {
    const std::string kv(*e);
    const std::string key = kv.substr(0, kv.find('='));
    if (!spec.env.count(key)) env_strings.push_back(kv);
  }
  for (const auto& [k, v] : spec.env) env_strings.push_back(k + "=" + v);
  std::vector<char*> envp, argv;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = spec.argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);

  const int err_fd = open(spec.stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (err_fd < 0) throw RuntimeFailure("cannot create " + spec.stderr_path + ": " + std::strerror(errno));
  int in[2], out[2], status_pipe[2];
  if (pipe2(in, O_CLOEXEC) != 0 || pipe2(out, O_CLOEXEC) != 0 || pipe2(status_pipe, O_CLOEXEC) != 0) {
    close(err_fd);
    throw RuntimeFailure(std::string("cannot create pipes: ") + std::strerror(errno));
  }
  // Larger pipes: a 640 x 640 image (1.2 MB) then goes in one or two writes instead of ~19.
  fcntl(in[1], F_SETPIPE_SZ, 1 << 20);
  fcntl(out[1], F_SETPIPE_SZ, 1 << 16);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    const int e = errno;
    for (int fd : {in[0], in[1], out[0], out[1], status_pipe[0], status_pipe[1], err_fd}) close(fd);
    throw RuntimeFailure(std::string("cannot fork: ") + std::strerror(e));
  }
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // omniloc died between fork and prctl
    // The signals omniloc ignores or handles must not carry over as "ignored" into the client.
    signal(SIGPIPE, SIG_DFL);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGHUP, SIG_DFL);
    int e = 0;
    if (dup2(in[0], 0) < 0 || dup2(out[1], 1) < 0 || dup2(err_fd, 2) < 0) e = errno;
    if (!e && !spec.cwd.empty() && chdir(spec.cwd.c_str()) != 0) e = errno;
    if (!e) {
      // No other descriptor of omniloc (sweep locks, result files) reaches the client.
      const int keep = status_pipe[1];
      if (keep > 3) close_range(3, static_cast<unsigned>(keep - 1), 0);
      close_range(static_cast<unsigned>(keep + 1), ~0U, 0);
      execve(spec.program.c_str(), argv.data(), envp.data());
      e = errno;
    }
    const ssize_t w = write(status_pipe[1], &e, sizeof e);
    (void)w;
    _exit(127);
  }
  pid_ = pid;
  setpgid(pid, pid);  // also from this side: no race with a signal sent right after fork
  interrupt::watch_group(pid);
  close(in[0]);
  close(out[1]);
  close(err_fd);
  close(status_pipe[1]);
  in_fd_ = in[1];
  out_fd_ = out[0];
  set_nonblocking(in_fd_);
  set_nonblocking(out_fd_);
  int child_errno = 0;
  ssize_t n;
  while ((n = read(status_pipe[0], &child_errno, sizeof child_errno)) < 0 && errno == EINTR) {
  }
  close(status_pipe[0]);
  if (n > 0) {
    terminate(std::chrono::milliseconds(0));
    throw RuntimeFailure("cannot start " + spec.program + " in " + spec.cwd + ": " + std::strerror(child_errno));
  }
}

ClientProcess::~ClientProcess() {
  terminate();
  if (in_fd_ >= 0) close(in_fd_);
  if (out_fd_ >= 0) close(out_fd_);
}

ClientProcess::Io ClientProcess::write_all(std::string_view bytes, Clock::time_point deadline, MessageReader& reader) {
  std::size_t done = 0;
  char buf[65536];
  while (done < bytes.size()) {
    if (in_fd_ < 0) return Io::kClosed;
    const ssize_t w = write(in_fd_, bytes.data() + done, bytes.size() - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno == EPIPE) return Io::kClosed;
    if (w < 0 && errno != EAGAIN) throw RuntimeFailure(std::string("writing to the client: ") + std::strerror(errno));
    const int wait = ms_until(deadline);
    if (wait == 0) return Io::kTimeout;
    pollfd fds[2] = {{in_fd_, POLLOUT, 0}, {out_fd_, POLLIN, 0}};
    const int nfds = stdout_eof_ ? 1 : 2;
    if (poll(fds, nfds, wait) < 0 && errno != EINTR) throw RuntimeFailure(std::string("poll: ") + std::strerror(errno));
    if (nfds == 2 && (fds[1].revents & (POLLIN | POLLHUP))) {
      const ssize_t r = read(out_fd_, buf, sizeof buf);
      if (r > 0) reader.feed(std::string_view(buf, static_cast<std::size_t>(r)));
      else if (r == 0) stdout_eof_ = true;
    }
    if (fds[0].revents & (POLLERR | POLLHUP)) return Io::kClosed;
  }
  return Io::kOk;
}

ClientProcess::Io ClientProcess::read_message(Clock::time_point deadline, MessageReader& reader, std::optional<Message>& out) {
  static thread_local std::vector<char> buf(1 << 20);
  for (;;) {
    if ((out = reader.next())) return Io::kOk;
    if (stdout_eof_) return Io::kClosed;
    const int wait = ms_until(deadline);
    pollfd fd{out_fd_, POLLIN, 0};
    const int p = poll(&fd, 1, wait);
    if (p < 0 && errno == EINTR) continue;
    if (p < 0) throw RuntimeFailure(std::string("poll: ") + std::strerror(errno));
    if (p == 0) return Io::kTimeout;
    const ssize_t r = read(out_fd_, buf.data(), buf.size());
    if (r > 0) reader.feed(std::string_view(buf.data(), static_cast<std::size_t>(r)));
    else if (r == 0) stdout_eof_ = true;
    else if (errno != EAGAIN && errno != EINTR) throw RuntimeFailure(std::string("reading from the client: ") + std::strerror(errno));
  }
}

void ClientProcess::close_stdin() {
  if (in_fd_ >= 0) close(in_fd_);
  in_fd_ = -1;
}

std::optional<int> ClientProcess::poll_exit() {
  if (status_) return status_;
  if (pid_ <= 0) return std::nullopt;
  siginfo_t info{};
  if (waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid == 0) return std::nullopt;
  // Exited: end what is left of its group while the zombie still holds the group id, then reap.
  kill(-pid_, SIGKILL);
  int st = 0;
  while (waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
  }
  status_ = st;
  interrupt::unwatch_group(pid_);
  return status_;
}

std::optional<int> ClientProcess::wait_exit(Clock::time_point deadline) {
  for (;;) {
    if (auto st = poll_exit()) return st;
    if (Clock::now() >= deadline) return std::nullopt;
    sleep_ms(std::min(5, std::max(1, ms_until(deadline))));
  }
}

void ClientProcess::terminate(std::chrono::milliseconds grace) {
  if (pid_ <= 0 || status_) return;
  close_stdin();
  kill(-pid_, SIGTERM);
  if (!wait_exit(Clock::now() + grace)) {
    kill(-pid_, SIGKILL);
    wait_exit(Clock::now() + std::chrono::seconds(10));
  }
}

std::string ClientProcess::stderr_tail(int lines) const {
  std::ifstream f(stderr_path_, std::ios::binary);
  if (!f) return "";
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - 16384);
  f.seekg(from);
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  std::size_t pos = text.size();
  for (int n = 0; n < lines && pos != std::string::npos && pos > 0; ++n) pos = text.rfind('\n', pos - 1);
  std::string tail = pos == std::string::npos || pos == 0 ? text : text.substr(pos + 1);
  if (from > 0 && (pos == std::string::npos || pos == 0)) tail = "..." + tail;
  return tail;
}

}  // namespace omniloc::external
