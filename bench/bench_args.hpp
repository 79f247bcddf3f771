// bench/bench_args.hpp: command-line parsing shared by the bench programs. Each program defines
// fesd_bench::usage() (its own usage text); the parsers below report bad values through it.
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "fesd/options.hpp"

namespace fesd_bench {

/// Prints "<program>: <why>" and the program's usage to stderr, then exits with exit_code.
[[noreturn]] void usage(const std::string& why, int exit_code = 2);

/// The non-empty pieces of s between separators.
inline std::vector<std::string> split(std::string_view s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char ch : s) {
    if (ch == sep) {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += ch;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

/// A positive integer, or usage() naming the flag.
inline int parse_int(const std::string& flag, const std::string& v) {
  try {
    std::size_t pos = 0;
    const int i = std::stoi(v, &pos);
    if (pos != v.size() || i < 1) throw std::invalid_argument(v);
    return i;
  } catch (const std::exception&) {
    usage(fmt::format("{} {}: expected a positive integer", flag, v));
  }
}

/// A positive number, or usage() naming the flag.
inline double parse_double(const std::string& flag, const std::string& v) {
  try {
    std::size_t pos = 0;
    const double d = std::stod(v, &pos);
    if (pos != v.size() || !(d > 0)) throw std::invalid_argument(v);
    return d;
  } catch (const std::exception&) {
    usage(fmt::format("{} {}: expected a positive number", flag, v));
  }
}

/// A non-empty comma-separated list of positive integers, or usage() naming the flag.
inline std::vector<int> parse_list(const std::string& flag, const std::string& v) {
  std::vector<int> out;
  for (const std::string& item : split(v, ',')) out.push_back(parse_int(flag, item));
  if (out.empty()) usage(flag + ": empty list");
  return out;
}

/// `--step-solver active_set|homotopy`, or usage() naming the flag.
inline fesd::StepSolver parse_step_solver(const std::string& flag, const std::string& v) {
  fesd::StepSolver s{};
  if (!fesd::parse(v, s)) usage(fmt::format("{} {}: expected active_set or homotopy", flag, v));
  return s;
}

}  // namespace fesd_bench
