// src/ocp/allocation.hpp: the OCP with a given allocation of the finite elements to the segments
// between switches (docs/formulation.md, "Switches held by the grid"), for a brute-force scan
// over every allocation (bench/ocp_robustness, tests/ocp): the reference of the allocation
// search.
#pragma once
#include <optional>
#include <vector>

#include "fesd/ocp.hpp"

namespace fesd::ocp_detail {

/// solve(ocp, options), then every control interval re-gridded from its solution to `count[j]`
/// elements in its segment j (FesdInterval::regrid) and the last NLP solved once more from
/// there with every active set fixed (kept whatever its cost; then re-gridded uniform on each
/// segment while that lowers the cost). Empty if the homotopy failed, an interval's number of
/// segments is not count.size() or the re-solve failed.
std::optional<OcpResult> solve_allocation(const Ocp& ocp, const OcpOptions& options,
                                          const std::vector<int>& count);

}  // namespace fesd::ocp_detail
