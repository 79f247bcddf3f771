// tests/discretization/sliding_exit_test.cpp: which active-set changes are sliding exits
// (FesdInterval::exit_regions, docs/formulation.md "Leaving a sliding mode"). The model of OCP
// (61) has two subsystems with two regions each: 0 phi_1 > 0, 1 phi_1 < 0 (subsystem 0), 2 phi_2
// > 0, 3 phi_2 < 0 (subsystem 1).
#include <vector>

#include <gtest/gtest.h>

#include "../../bench/sliding_ocp.hpp"
#include "discretization/fesd_interval.hpp"

namespace {

using fesd::discretization::FesdInterval;
using V = std::vector<int>;

TEST(SlidingExit, OnlyARegionLeftWhileAnotherOfItsSubsystemStaysIsAnExit) {
  const fesd::Pss m = fesd_bench::sliding_model();
  // Crossings (no region of the subsystem in common), entering a sliding mode, no change.
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 2}, {1, 2}), V{});
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 2}, {0, 2, 3}), V{});
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 1, 2, 3}, {0, 1, 2, 3}), V{});
  // Leaving the sliding mode on phi_2 = 0 into phi_2 < 0: region 2 is left.
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 2, 3}, {0, 3}), V{2});
  // Leaving the co-dimension-2 set on both surfaces at once: one exit per subsystem.
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 1, 2, 3}, {1, 3}), (V{0, 2}));
  // Leaving one surface while crossing the other: only the sliding subsystem counts.
  EXPECT_EQ(FesdInterval::exit_regions(m, {0, 1, 2}, {1, 3}), V{0});
}

}  // namespace
