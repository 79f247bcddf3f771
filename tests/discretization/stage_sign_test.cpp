// tests/discretization/stage_sign_test.cpp: where the stage LPs keep lambda >= 0
// (DiscretizationOptions::stage_lambda_sign, docs/formulation.md).
//
// "boundary": lambda >= 0 only at the element boundary points; at the other stages lambda is free
// and enters exactly one complementarity constraint, its own stage's theta * lambda, relaxed on
// both sides. "auto" picks "boundary" for Lobatto IIIC and explicit RK, "all" otherwise.
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "mpcc/relaxation.hpp"

namespace {

using fesd::RkScheme;
using fesd::StageLambdaSign;

struct Crossing {  // x' in 2 - sign(x), Example 3(a)
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int r, const T*, const T*, const T*, T* f) const {
    f[0] = T(r == 0 ? 1.0 : 3.0);
  }
};

struct Built {
  fesd::nlp::BlockNlp nlp;
  std::unique_ptr<fesd::discretization::FesdInterval> iv;
};

std::unique_ptr<Built> build(RkScheme scheme, int n_s, StageLambdaSign sign, bool fesd = true,
                             fesd::CrossComp cross = fesd::CrossComp::StageSum) {
  static const fesd::Pss model = fesd::make_pss(
      Crossing{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  fesd::DiscretizationOptions d;
  d.rk_scheme = scheme;
  d.n_s = n_s;
  d.N_FE = 3;
  d.use_fesd = fesd;
  d.stage_lambda_sign = sign;
  d.cross_comp = cross;
  auto b = std::make_unique<Built>();
  auto vars = [&](int n) {
    std::vector<int> v;
    const int first = b->nlp.add_variables(n, 0.0, 0.0, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  fesd::discretization::IntervalInputs in;
  in.s0 = vars(1);
  in.lambda_start = vars(model.n_theta());
  in.mu_start = vars(model.n_sys());
  in.T = 1.0;
  b->iv = std::make_unique<fesd::discretization::FesdInterval>(model,
                                                               fesd::make_tableau(scheme, n_s), d);
  b->iv->build(b->nlp, in);
  return b;
}

TEST(StageLambdaSign, AutoPicksBoundaryForLowStageOrderSchemes) {
  EXPECT_TRUE(build(RkScheme::LobattoIIIC, 3, StageLambdaSign::Auto)->iv->boundary_sign());
  EXPECT_TRUE(build(RkScheme::ExplicitRK, 2, StageLambdaSign::Auto)->iv->boundary_sign());
  EXPECT_FALSE(build(RkScheme::RadauIIA, 3, StageLambdaSign::Auto)->iv->boundary_sign());
  EXPECT_FALSE(build(RkScheme::GaussLegendre, 2, StageLambdaSign::Auto)->iv->boundary_sign());
  EXPECT_FALSE(build(RkScheme::LobattoIIIA, 3, StageLambdaSign::Auto)->iv->boundary_sign());
  EXPECT_TRUE(build(RkScheme::RadauIIA, 3, StageLambdaSign::Boundary)->iv->boundary_sign());
  EXPECT_FALSE(build(RkScheme::LobattoIIIC, 3, StageLambdaSign::All)->iv->boundary_sign());
  // The standard method has no cross complementarity: the option does not apply.
  EXPECT_FALSE(
      build(RkScheme::LobattoIIIC, 3, StageLambdaSign::Boundary, false)->iv->boundary_sign());
}

// Lobatto IIIC is stiffly accurate: its last stage is x_{n+1} and keeps lambda >= 0; the others
// are free.
TEST(StageLambdaSign, BoundaryFreesOnlyInteriorStagesOfLobattoIIIC) {
  const auto b = build(RkScheme::LobattoIIIC, 3, StageLambdaSign::Boundary);
  const auto& iv = *b->iv;
  for (int n = 0; n < iv.N_FE(); ++n)
    for (int s = 0; s < iv.n_s(); ++s)
      for (int r = 0; r < 2; ++r) {
        const double lb = b->nlp.x_lb[iv.lambda(n, s, r)];
        if (s == iv.n_s() - 1)
          EXPECT_EQ(lb, 0.0) << "n " << n << " s " << s;
        else
          EXPECT_EQ(lb, -fesd::nlp::kInf) << "n " << n << " s " << s;
      }
}

// Explicit RK is not stiffly accurate: every stage is free, and every element (the last one too)
// gets the boundary values (33) at its end, the signed point that closes the element.
TEST(StageLambdaSign, BoundaryGivesEveryExplicitElementItsEndPoint) {
  const auto b = build(RkScheme::ExplicitRK, 2, StageLambdaSign::Boundary);
  const auto& iv = *b->iv;
  for (int n = 0; n < iv.N_FE(); ++n) {
    EXPECT_GE(iv.lambda_end(n, 0), 0) << "element " << n;
    EXPECT_EQ(b->nlp.x_lb[iv.lambda_end(n, 0)], 0.0);
    for (int s = 0; s < iv.n_s(); ++s) EXPECT_EQ(b->nlp.x_lb[iv.lambda(n, s, 0)], -fesd::nlp::kInf);
  }
}

// A free lambda appears in exactly one constraint: its own stage's product, two-sided. Every other
// constraint is a sum of products of nonnegative variables, as the Scholtes relaxation assumes.
TEST(StageLambdaSign, FreeLambdasOnlyInTheirOwnTwoSidedPair) {
  for (auto cross : {fesd::CrossComp::Sparse, fesd::CrossComp::StageSum, fesd::CrossComp::Element,
                     fesd::CrossComp::Neighbor}) {
    SCOPED_TRACE(static_cast<int>(cross));
    const auto b = build(RkScheme::LobattoIIIC, 3, StageLambdaSign::Boundary, true, cross);
    const auto& nlp = b->nlp;
    int two_sided = 0;
    for (const auto& g : b->iv->groups()) {
      bool has_free = false;
      for (const auto& pair : g.pairs) has_free = has_free || nlp.x_lb[pair.b] < 0;
      if (g.two_sided) {
        ++two_sided;
        ASSERT_EQ(g.pairs.size(), 1U);
        EXPECT_TRUE(has_free);
      } else {
        EXPECT_FALSE(has_free);
      }
    }
    // N_FE = 3 elements x 2 free stages x 2 regions.
    EXPECT_EQ(two_sided, 3 * 2 * 2);
  }
}

// The relaxation of a two-sided group is -sigma <= theta * lambda <= sigma.
TEST(StageLambdaSign, TwoSidedRowsFollowSigmaOnBothSides) {
  auto b = build(RkScheme::ExplicitRK, 2, StageLambdaSign::Boundary);
  const std::vector<int> rows = fesd::mpcc::add_scholtes_rows(b->nlp, b->iv->groups());
  fesd::mpcc::set_sigma(b->nlp, rows, 1e-3);
  int two_sided = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(b->nlp.g_ub[rows[k]], 1e-3);
    if (b->iv->groups()[k].two_sided) {
      ++two_sided;
      EXPECT_EQ(b->nlp.g_lb[rows[k]], -1e-3);
    } else {
      EXPECT_EQ(b->nlp.g_lb[rows[k]], -fesd::nlp::kInf);
    }
  }
  EXPECT_EQ(two_sided, 3 * 2 * 2);
}

}  // namespace
