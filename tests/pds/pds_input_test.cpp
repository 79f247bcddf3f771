// Bad input for projected dynamical systems: one clear fesd::Error each, before any computation.
#include <cmath>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "discretization/pds_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/pds.hpp"

namespace {

// C = {x : x2 + 1 >= 0} (Example 1 of papers/fesd-pds.txt); `twice` repeats the constraint.
struct HalfPlane {
  bool twice = false;
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[1] + 1.0;
    if (twice) c[1] = 2.0 * (x[1] + 1.0);
  }
  template <class T>
  void f(const T* x, const T*, const T*, T* f) const {
    f[0] = x[1];
    f[1] = -x[0];
  }
};

fesd::Pds half_plane(bool twice = false) {
  return fesd::make_pds(HalfPlane{twice}, fesd::PdsDims{.n_x = 2, .n_c = twice ? 2 : 1});
}

template <class E>
std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(PdsInput, NoConstraintRejected) {
  const std::string m = message_of<fesd::InvalidModel>(
      [] { fesd::make_pds(HalfPlane{}, fesd::PdsDims{.n_x = 2, .n_c = 0}); });
  EXPECT_NE(m.find("n_c = 0"), std::string::npos) << m;
}

TEST(PdsInput, InitialStateOutsideCRejected) {
  const std::string m = message_of<fesd::InvalidModel>(
      [] { fesd::integrate(half_plane(), Eigen::Vector2d(0.0, -1.5), 1.0, 1); });
  EXPECT_NE(m.find("x0 lies outside C"), std::string::npos) << m;
  EXPECT_NE(m.find("c1(x0) = -0.5"), std::string::npos) << m;
  // Within x0_tol: accepted (a state on the boundary up to round-off).
  fesd::Pds model = half_plane();
  model.x0_tol = 1e-6;
  fesd::IntegratorOptions o;
  o.discretization.N_FE = 2;
  const auto r = fesd::integrate(model, Eigen::Vector2d(0.5, -1.0 - 1e-7), 0.1, 1, o);
  EXPECT_EQ(r.status, fesd::Status::Success) << r.message;
}

TEST(PdsInput, SchemesWithoutLastNodeOneRejected) {
  for (auto scheme :
       {fesd::RkScheme::GaussLegendre, fesd::RkScheme::LobattoIIIA, fesd::RkScheme::ExplicitRK}) {
    fesd::IntegratorOptions o;
    o.discretization.rk_scheme = scheme;
    o.discretization.n_s = 2;
    const std::string m = message_of<fesd::InvalidOption>(
        [&] { fesd::integrate(half_plane(), Eigen::Vector2d(1.0, 1.0), 1.0, 1, o); });
    EXPECT_NE(m.find("radau_iia, lobatto_iiic"), std::string::npos) << m;
  }
}

TEST(PdsInput, NonPositiveMRejected) {
  fesd::PdsOptions pds;
  pds.M = 0;
  const std::string m = message_of<fesd::InvalidOption>(
      [&] { fesd::integrate(half_plane(), Eigen::Vector2d(1.0, 1.0), 1.0, 1, {}, {}, {}, pds); });
  EXPECT_NE(m.find("M = 0"), std::string::npos) << m;
}

TEST(PdsInput, SizesAndNonFiniteValuesRejected) {
  EXPECT_NE(message_of<fesd::InvalidModel>([] {
              fesd::integrate(half_plane(), Eigen::Vector3d(1.0, 1.0, 1.0), 1.0, 1);
            }).find("x0 has 3 entries"),
            std::string::npos);
  EXPECT_NE(message_of<fesd::InvalidModel>([] {
              fesd::integrate(half_plane(), Eigen::Vector2d(NAN, 1.0), 1.0, 1);
            }).find("must be finite"),
            std::string::npos);
}

// Linearly dependent constraint gradients at x0 (c2 = 2 c1, both active): a warning.
TEST(PdsInput, LicqFailureAtX0Warns) {
  fesd::IntegratorOptions o;
  o.discretization.N_FE = 2;
  const auto r = fesd::integrate(half_plane(true), Eigen::Vector2d(0.5, -1.0), 0.1, 1, o);
  bool warned = false;
  for (const auto& w : r.summary.warnings) warned = warned || w.find("LICQ fails") != w.npos;
  EXPECT_TRUE(warned);
}

}  // namespace

// The warm starts of PDS steps (docs/pds.md, "Warm starts"): IPOPT's three pushes are 1e-9 unless
// [ipopt] sets them.
TEST(PdsWarmStart, SmallPushesUnlessGiven) {
  fesd::NlpOptions o;
  o.extra = {{"warm_start_bound_push", "1e-4"}, {"mu_strategy", "monotone"}};
  const fesd::NlpOptions p = fesd::discretization::pds_nlp_options(o);
  auto value = [&](const std::string& name) {
    int found = 0;
    std::string v;
    for (const auto& [k, val] : p.extra)
      if (k == name) ++found, v = val;
    EXPECT_EQ(found, 1) << name;
    return v;
  };
  EXPECT_EQ(value("warm_start_bound_push"), "1e-4");
  EXPECT_EQ(value("warm_start_slack_bound_push"), "1e-09");
  EXPECT_EQ(value("warm_start_mult_bound_push"), "1e-09");
  EXPECT_EQ(value("mu_strategy"), "monotone");
}
