// src/io/plot.cpp: plots of an integrator result with gnuplot (PNG or SVG). The data go inline in
// the script (gnuplot data blocks), the script goes to gnuplot's standard input: no temporary
// files.
//
// Layout: top panel the states x(t) at the finite-element boundaries, one line per state, with a
// dashed vertical line at every switching time t_s; bottom panel the step sizes h_n drawn as a
// step function over [t_n, t_{n+1}] (log scale if they span more than two decades).
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

namespace fesd {
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

// Locale-independent %.17g; gnuplot reads NaN as an undefined point.
std::string number(double v) {
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

std::vector<std::string> state_names_of(const Pss& model, std::size_t n) {
  std::vector<std::string> names(n);
  for (std::size_t i = 0; i < n; ++i) {
    names[i] = i < model.state_names.size() && !model.state_names[i].empty()
                   ? model.state_names[i]
                   : 'x' + std::to_string(i + 1);
  }
  return names;
}

std::string terminal_for(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == ".png") return "set terminal pngcairo size 1000,700 enhanced font 'Sans,10'\n";
  if (ext == ".svg") {
    return "set terminal svg size 1000,700 dynamic enhanced font 'Sans,10' "
           "background rgb 'white'\n";
  }
  const std::string shown = ext.empty() ? "no extension" : "extension '" + ext + "'";
  throw IoError("cannot plot to '" + path + "': unsupported " + shown + " (supported: .png, .svg)");
}

std::string make_script(const IntegratorResult& result, const Pss& model, const std::string& path,
                        const std::string& title, const std::string& terminal) {
  const std::size_t n_points = std::min(result.t.size(), result.x.size());
  const std::size_t n_x = n_points > 0 ? static_cast<std::size_t>(result.x[0].size()) : 0;
  const std::vector<std::string> names = state_names_of(model, n_x);
  const double t0 = result.t.front(), t_end = result.t[n_points - 1];

  std::string s = terminal;
  s += "set output " + gp_string(path) + "\n";
  s += "set encoding utf8\n";

  // Inline data: the states at the element boundaries ...
  s += "$states << EOD\n";
  for (std::size_t n = 0; n < n_points; ++n) {
    s += number(result.t[n]);
    for (std::size_t i = 0; i < n_x; ++i) {
      s += ' ';
      s += i < static_cast<std::size_t>(result.x[n].size())
               ? number(result.x[n][static_cast<Eigen::Index>(i)])
               : std::string("NaN");
    }
    s += '\n';
  }
  s += "EOD\n";
  // ... and h_n at t_n, with h_{N-1} repeated at t_N so that the last step is drawn to the end.
  const std::size_t n_h = std::min(result.h.size(), n_points > 0 ? n_points - 1 : 0);
  double h_min = INFINITY, h_max = -INFINITY;
  s += "$steps << EOD\n";
  for (std::size_t n = 0; n < n_h; ++n) {
    s += number(result.t[n]) + ' ' + number(result.h[n]) + '\n';
    if (std::isfinite(result.h[n])) {
      h_min = std::min(h_min, result.h[n]);
      h_max = std::max(h_max, result.h[n]);
    }
  }
  if (n_h > 0) s += number(result.t[n_h]) + ' ' + number(result.h[n_h - 1]) + '\n';
  s += "EOD\n";

  s += title.empty() ? "set multiplot\n"
                     : "set multiplot title " + gp_string(title) + " noenhanced font ',12'\n";
  const double top = title.empty() ? 1.0 : 0.95;
  s += "set lmargin 12\nset rmargin 20\n";
  s += "set grid\nset key outside right top noenhanced\n";
  if (t_end > t0) s += "set xrange [" + number(t0) + ":" + number(t_end) + "]\n";

  // The switching times: dashed lines in both panels, labels in the top one.
  const std::vector<double> ts = result.switch_times();
  const bool label_switches = ts.size() <= 20;
  int tag = 1;
  for (double t_s : ts) {
    if (!std::isfinite(t_s)) continue;
    s += "set arrow " + std::to_string(tag) + " from " + number(t_s) + ", graph 0 to " +
         number(t_s) + ", graph 1 nohead dashtype 2 linewidth 1 linecolor rgb '#707070' back\n";
    if (label_switches) {
      s += "set label " + std::to_string(tag) + " 't_s' at " + number(t_s) +
           ", graph 1 offset 0,0.6 center textcolor rgb '#505050'\n";
    }
    ++tag;
  }

  // Top panel: the states.
  s += "set origin 0," + number(0.36) + "\nset size 1," + number(top - 0.36) + "\n";
  s += "set tmargin 2\nset bmargin 1\nset format x ''\nunset xlabel\nset ylabel 'x(t)'\n";
  s += "set offsets 0, 0, graph 0.05, graph 0.05\n";
  s += "plot ";
  for (std::size_t i = 0; i < n_x; ++i) {
    s += "$states using 1:" + std::to_string(i + 2) + " with lines linewidth 2 title " +
         gp_string(names[i]) + ", ";
  }
  s += ts.empty() ? "NaN notitle\n"
                  : "NaN with lines dashtype 2 linecolor rgb '#707070' title 'switches'\n";
  s += "unset label\n";

  // Bottom panel: the step sizes.
  s += "set origin 0,0\nset size 1," + number(0.36) + "\n";
  s += "set tmargin 0.5\nset bmargin 3.5\nset format x\nset xlabel 't'\nset offsets 0, 0, 0, 0\n";
  s += "set ylabel 'h_n' enhanced\n";
  if (n_h == 0 || !(h_max >= h_min)) {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  } else {
    if (h_min > 0 && h_max > 100 * h_min) {
      s += "set logscale y\nset format y '10^{%L}'\n";
      s += "set yrange [" + number(h_min / 2) + ":" + number(h_max * 2) + "]\n";
    } else if (h_max > h_min) {
      const double pad = 0.1 * (h_max - h_min);
      s += "set yrange [" + number(h_min - pad) + ":" + number(h_max + pad) + "]\n";
    } else {
      const double pad = h_max != 0 ? 0.25 * std::abs(h_max) : 1.0;
      s += "set yrange [" + number(h_max - pad) + ":" + number(h_max + pad) + "]\n";
    }
    s += "plot $steps using 1:2 with steps linewidth 2 linecolor rgb '#1f77b4' title 'h_n'\n";
  }
  s += "unset multiplot\nunset output\n";
  return s;
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

void write_plot(const IntegratorResult& result, const Pss& model, const std::string& path,
                const std::string& title) {
  const std::string terminal = terminal_for(path);
  if (path.find_first_of("\n\r") != std::string::npos) {
    throw IoError("cannot plot to '" + path + "': the path contains a line break");
  }
  if (std::min(result.t.size(), result.x.size()) == 0) {
    throw IoError("cannot plot to '" + path + "': the result has no time points");
  }
  if (!on_path("gnuplot")) throw IoError(std::string(kMissingGnuplot));

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
    code = run_gnuplot(make_script(result, model, path, title, terminal), err);
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

}  // namespace fesd
