// What SIGINT, SIGTERM and SIGHUP do to the outputs being written, and the removal of what a
// killed run left (backlash/output/signals.hpp; the registry of temporaries: temporaries.hpp).
// The handler only writes the signal's number into a pipe (async-signal-safe); a watcher
// thread reads it and does the cleanup in ordinary code, then ends the process by the signal.
#include "backlash/output/signals.hpp"

#include "temporaries.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <map>
#include <thread>
#include <vector>

namespace backlash::output {

namespace fs = std::filesystem;

namespace {

constexpr int handled_signals[] = {SIGINT, SIGTERM, SIGHUP};

struct Registry {
  std::recursive_mutex mutex;
  std::map<std::uint64_t, fs::path> paths;
  std::uint64_t next = 0;
};

// Never destroyed: the watcher may use it while the process exits.
Registry& registry() {
  static Registry* const instance = new Registry;
  return *instance;
}

std::atomic<int> stop_scopes{0};
volatile std::sig_atomic_t stop_flag = 0;
int signal_pipe[2] = {-1, -1};

extern "C" void on_signal(int number) {
  if (stop_scopes.load() > 0) {
    stop_flag = 1;
    return;
  }
  const int saved = errno;
  const auto byte = static_cast<unsigned char>(number);
  [[maybe_unused]] const ssize_t written = ::write(signal_pipe[1], &byte, 1);
  errno = saved;
}

// Removes every registered temporary (a few tries: the work goes on meanwhile and may still
// add files to a folder being removed).
void remove_registered() {
  for (const auto& [id, path] : registry().paths)
    for (int attempt = 0; attempt < 5; ++attempt) {
      std::error_code error;
      fs::remove_all(path, error);
      if (!error) break;
    }
}

// The signal's default action, from this thread: the process ends as killed by it.
[[noreturn]] void end_by(int number) {
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  ::sigaction(number, &default_action, nullptr);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, number);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(number);
  ::_exit(128 + number);
}

void watch() {
  for (;;) {
    unsigned char byte = 0;
    const ssize_t count = ::read(signal_pipe[0], &byte, 1);
    if (count < 0 && errno == EINTR) continue;
    if (count != 1) return;
    const auto held = detail::hold_temporaries();  // kept: the process ends holding it
    remove_registered();
    end_by(byte);
  }
}

void install() {
  if (::pipe2(signal_pipe, O_CLOEXEC) != 0) return;  // no cleanup on signals; the stale removal remains
  std::thread(watch).detach();
  for (const int number : handled_signals) {
    struct sigaction old {};
    if (::sigaction(number, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;  // nohup: stays ignored
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(number, &action, nullptr);
  }
}

// "PID-XXXXXX" → PID (0 when the name is not of that form).
long pid_of(const std::string& rest) {
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash > 9 || rest.size() != dash + 7) return 0;
  long pid = 0;
  for (std::size_t k = 0; k < dash; ++k) {
    if (rest[k] < '0' || rest[k] > '9') return 0;
    pid = 10 * pid + (rest[k] - '0');
  }
  return pid;
}

bool alive(long pid) { return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM; }

// Removes `path` if no process holds its lock.
void remove_if_unlocked(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return;
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  ::close(fd);
}

}  // namespace

namespace detail {

std::unique_lock<std::recursive_mutex> hold_temporaries() { return std::unique_lock(registry().mutex); }

std::string temporary_prefix(const fs::path& target) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::string name = ".";  // built by appending: GCC 12's -Wrestrict misreads the chained operator+
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  return (folder / name).string();
}

std::uint64_t track_temporary(const fs::path& path) {
  const auto held = hold_temporaries();
  const std::uint64_t ticket = ++registry().next;
  registry().paths.emplace(ticket, path);
  return ticket;
}

void forget_temporary(std::uint64_t& ticket) {
  if (ticket == 0) return;
  const auto held = hold_temporaries();
  registry().paths.erase(ticket);
  ticket = 0;
}

void lock_temporary(int fd) { ::flock(fd, LOCK_EX | LOCK_NB); }  // a fresh file or folder: nobody else holds it

}  // namespace detail

void clean_up_on_signals() {
  static std::once_flag once;
  std::call_once(once, install);
}

StopOnSignal::StopOnSignal() { ++stop_scopes; }
StopOnSignal::~StopOnSignal() { --stop_scopes; }
bool StopOnSignal::requested() { return stop_flag != 0; }

void remove_stale_temporaries(const fs::path& target) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::string head = ".";  // built by appending: GCC 12's -Wrestrict misreads the chained operator+
  head += target.filename().string();
  head += ".tmp-";
  std::vector<fs::path> stale;  // listed first, removed after: not while reading the folder
  std::error_code error;
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (name.rfind(head, 0) != 0) continue;
    const long pid = pid_of(name.substr(head.size()));
    if (pid > 0 && pid != ::getpid() && !alive(pid)) stale.push_back(entry->path());
  }
  for (const fs::path& path : stale) remove_if_unlocked(path);
}

}  // namespace backlash::output
