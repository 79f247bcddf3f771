// Pieces of the human-readable reports shared by the integrator and the OCP summaries.
#pragma once
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "fesd/integrator.hpp"

namespace fesd::detail {

/// "    t_s = 1.5   active regions {1,3} -> {1,2,3}\n": regions numbered from 1 like the
/// paper's R_1, ..., R_n (the JSON output keeps the 0-based indices of SwitchEvent).
inline std::string format_switch(const SwitchEvent& s) {
  auto set = [](const std::vector<int>& a) {
    std::vector<int> one_based(a.begin(), a.end());
    for (int& v : one_based) ++v;
    return fmt::format("{{{}}}", fmt::join(one_based, ","));
  };
  return fmt::format("    t_s = {:.12g}   active regions {} -> {}\n", s.t, set(s.before),
                     set(s.after));
}

}  // namespace fesd::detail
