// src/ocp/resolve_account.hpp: the bookkeeping of the OCP's re-solves after the homotopy
// (pinning, held switches, touches, the allocation search; src/ocp/ocp.cpp).
#pragma once
#include <vector>

#include "fesd/summary.hpp"
#include "mpcc/problem.hpp"

namespace fesd::ocp_detail {

/// Books the homotopy and each re-solve after it into the result's summary and rows, and counts
/// the re-solves in a row that did not converge (IPOPT's status or the complementarity residual;
/// a converged one, kept or not for its cost, resets the count). After kMaxFailedInARow of them
/// the remaining re-solves are skipped (and counted in `skipped`): on the gearboxes
/// (docs/nosnoc-examples.md rows 30, 31) every re-solve after the first failed ones stopped at
/// kSolveAgainMaxIter as well, 3-7 s each.
struct ResolveAccount {
  static constexpr int kMaxFailedInARow = 3;
  Summary& summary;
  std::vector<HomotopyRow>& rows;
  int failed_in_a_row = 0;
  int skipped = 0;
  void operator()(const mpcc::HomotopyResult& h) {
    mpcc::add_to_summary(h, summary, rows);
    failed_in_a_row = h.status == Status::Success ? 0 : failed_in_a_row + 1;
  }
  bool exhausted() const { return failed_in_a_row >= kMaxFailedInARow; }
  /// True (and the re-solve counted as skipped) if the account is exhausted.
  bool skip() {
    if (!exhausted()) return false;
    ++skipped;
    return true;
  }
};

}  // namespace fesd::ocp_detail
