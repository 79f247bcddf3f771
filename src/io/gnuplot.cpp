// src/io/gnuplot.cpp: gnuplot as a child process for the plot writers (see gnuplot.hpp).
#include "io/gnuplot.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "fesd/error.hpp"
#include "fesd/io.hpp"

extern char** environ;

namespace fesd::io_detail {
namespace {

constexpr std::string_view kMissingGnuplot =
    "gnuplot not found: install gnuplot-nox (scripts/install-deps.sh)";
constexpr std::size_t kMaxCapturedStderr = 16 * 1024;

// True if an executable `name` is on PATH.
bool on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string_view dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  while (true) {
    const std::size_t colon = dirs.find(':');
    std::string candidate(dirs.substr(0, colon));
    if (candidate.empty()) candidate.push_back('.');
    candidate += '/';
    candidate += name;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        ::access(candidate.c_str(), X_OK) == 0) {
      return true;
    }
    if (colon == std::string_view::npos) return false;
    dirs.remove_prefix(colon + 1);
  }
}

// Closes fds on scope exit.
struct Fd {
  int fd = -1;
  ~Fd() { reset(); }
  void reset() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

// Runs gnuplot with `script` on standard input. Returns its exit status (-1 if killed by a signal)
// and what it wrote to stderr (truncated).
int run_gnuplot(const std::string& script, std::string& err) {
  // Standard input through a socket pair so that a gnuplot that exits early gives EPIPE from
  // send(MSG_NOSIGNAL) instead of SIGPIPE for the whole process.
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) {
    throw IoError(std::string("cannot run gnuplot: socketpair: ") + std::strerror(errno));
  }
  Fd in_parent{sv[0]}, in_child{sv[1]};
  int pe[2];
  if (::pipe2(pe, O_CLOEXEC) != 0) {
    throw IoError(std::string("cannot run gnuplot: pipe: ") + std::strerror(errno));
  }
  Fd err_parent{pe[0]}, err_child{pe[1]};

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_child.fd, STDIN_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, err_child.fd, STDERR_FILENO);
  char arg0[] = "gnuplot";
  char* argv[] = {arg0, nullptr};
  pid_t pid = 0;
  const int spawn_error = ::posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error == ENOENT) throw IoError(std::string(kMissingGnuplot));
  if (spawn_error != 0) {
    throw IoError(std::string("cannot run gnuplot: ") + std::strerror(spawn_error));
  }
  in_child.reset();
  err_child.reset();
  ::fcntl(in_parent.fd, F_SETFL, ::fcntl(in_parent.fd, F_GETFL) | O_NONBLOCK);

  // Feed the script and collect stderr at the same time (either could fill its buffer).
  std::size_t sent = 0;
  if (script.empty()) in_parent.reset();
  while (in_parent.fd >= 0 || err_parent.fd >= 0) {
    pollfd fds[2];
    nfds_t n = 0;
    int in_index = -1, err_index = -1;
    if (in_parent.fd >= 0) {
      in_index = static_cast<int>(n);
      fds[n++] = pollfd{in_parent.fd, POLLOUT, 0};
    }
    if (err_parent.fd >= 0) {
      err_index = static_cast<int>(n);
      fds[n++] = pollfd{err_parent.fd, POLLIN, 0};
    }
    if (::poll(fds, n, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (in_index >= 0 && fds[in_index].revents != 0) {
      const ssize_t w =
          ::send(in_parent.fd, script.data() + sent, script.size() - sent, MSG_NOSIGNAL);
      if (w > 0) {
        sent += static_cast<std::size_t>(w);
        if (sent == script.size()) in_parent.reset();
      } else if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        in_parent.reset();  // gnuplot stopped reading (it exited); its status tells why
      }
    }
    if (err_index >= 0 && fds[err_index].revents != 0) {
      char buf[4096];
      const ssize_t r = ::read(err_parent.fd, buf, sizeof buf);
      if (r > 0) {
        const std::size_t room = kMaxCapturedStderr - std::min(err.size(), kMaxCapturedStderr);
        err.append(buf, std::min(room, static_cast<std::size_t>(r)));
      } else if (r == 0 || (errno != EAGAIN && errno != EINTR)) {
        err_parent.reset();
      }
    }
  }
  in_parent.reset();
  err_parent.reset();

  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      throw IoError(std::string("cannot run gnuplot: waitpid: ") + std::strerror(errno));
    }
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The last non-empty lines of gnuplot's stderr, joined into one line.
std::string summarize(const std::string& err) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= err.size()) {
    std::size_t end = err.find('\n', start);
    if (end == std::string::npos) end = err.size();
    std::string line = err.substr(start, end - start);
    const std::size_t first = line.find_first_not_of(" \t\r^");
    if (first != std::string::npos) lines.push_back(line.substr(first));
    start = end + 1;
  }
  std::string out;
  const std::size_t keep = 3;
  for (std::size_t i = lines.size() > keep ? lines.size() - keep : 0; i < lines.size(); ++i) {
    if (!out.empty()) out += "; ";
    out += lines[i];
  }
  return out;
}

}  // namespace

// Locale-independent %.17g; gnuplot reads NaN as an undefined point.
std::string gp_number(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  return std::string(buf, r.ptr);
}

// A gnuplot single-quoted string: no escapes except '' for a quote. Line breaks would end the
// command, so they become spaces.
std::string gp_string(std::string_view s) {
  std::string out = "'";
  for (char ch : s) {
    if (ch == '\'') {
      out += "''";
    } else if (ch == '\n' || ch == '\r') {
      out += ' ';
    } else {
      out += ch;
    }
  }
  out += '\'';
  return out;
}

std::vector<std::string> names_or_default(const std::vector<std::string>& names, std::size_t n,
                                          std::string_view prefix) {
  std::vector<std::string> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = i < names.size() && !names[i].empty() ? names[i]
                                                   : std::string(prefix) + std::to_string(i + 1);
  }
  return out;
}

std::string terminal_for(const std::string& path, int width, int height) {
  if (path.find_first_of("\n\r") != std::string::npos) {
    throw IoError("cannot plot to '" + path + "': the path contains a line break");
  }
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  if (ext == ".png") return "set terminal pngcairo size " + size + " enhanced font 'Sans,10'\n";
  if (ext == ".svg") {
    return "set terminal svg size " + size + " dynamic enhanced font 'Sans,10' " +
           "background rgb 'white'\n";
  }
  const std::string shown = ext.empty() ? "no extension" : "extension '" + ext + "'";
  throw IoError("cannot plot to '" + path + "': unsupported " + shown + " (supported: .png, .svg)");
}

void run_plot_script(const std::string& path, const std::string& script) {
  require_gnuplot();

  // Open the file ourselves first: a clear message if it cannot be written, and gnuplot never
  // falls back to writing the image to its standard output.
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fclose(f);
  } else {
    throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  }

  std::string err;
  int code = -1;
  try {
    code = run_gnuplot(script, err);
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (code != 0 || ec || size == 0) {
    std::remove(path.c_str());
    std::string what = "gnuplot failed to write '" + path + "'";
    if (code > 0) what += " (exit status " + std::to_string(code) + ")";
    if (code < 0) what += " (killed by a signal)";
    const std::string detail = summarize(err);
    if (!detail.empty()) what += ": " + detail;
    throw IoError(what);
  }
}

}  // namespace fesd::io_detail

namespace fesd {

void require_gnuplot() {
  if (!io_detail::on_path("gnuplot")) throw IoError(std::string(io_detail::kMissingGnuplot));
}

}  // namespace fesd
