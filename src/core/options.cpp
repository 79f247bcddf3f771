// Option names, parsing and validation: one table per enum, one rule per line.
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "fesd/error.hpp"
#include "fesd/options.hpp"

namespace fesd {
namespace {

template <class E, std::size_t K>
bool parse_from(const std::array<std::pair<E, std::string_view>, K>& table, std::string_view name,
                E& out) {
  for (const auto& [v, n] : table)
    if (n == name) {
      out = v;
      return true;
    }
  return false;
}
template <class E, std::size_t K>
std::string_view name_from(const std::array<std::pair<E, std::string_view>, K>& table, E v) {
  for (const auto& [e, n] : table)
    if (e == v) return n;
  return "unknown";
}

constexpr std::array<std::pair<CrossComp, std::string_view>, 4> kCrossComp{{
    {CrossComp::Sparse, "sparse"},
    {CrossComp::StageSum, "stage_sum"},
    {CrossComp::Element, "element"},
    {CrossComp::Neighbor, "neighbor"},
}};
constexpr std::array<std::pair<StepEq, std::string_view>, 5> kStepEq{{
    {StepEq::None, "none"},
    {StepEq::Eta, "eta"},
    {StepEq::EtaTanh, "eta_tanh"},
    {StepEq::HeuristicMean, "heuristic_mean"},
    {StepEq::L2Relaxed, "l2_relaxed"},
}};
constexpr std::array<std::pair<StageLambdaSign, std::string_view>, 3> kStageLambdaSign{{
    {StageLambdaSign::All, "all"},
    {StageLambdaSign::Boundary, "boundary"},
    {StageLambdaSign::Auto, "auto"},
}};
constexpr std::array<std::pair<MpccMode, std::string_view>, 5> kMpccMode{{
    {MpccMode::ScholtesIneq, "scholtes_ineq"},
    {MpccMode::ScholtesEq, "scholtes_eq"},
    {MpccMode::FischerBurmeister, "fischer_burmeister"},
    {MpccMode::L1Penalty, "ell_1_penalty"},
    {MpccMode::ElasticIneq, "elastic_ineq"},
}};

void require(std::vector<std::string>& out, bool ok, const std::string& what) {
  if (!ok) out.push_back(what);
}
bool finite_positive(double v) {
  return std::isfinite(v) && v > 0;
}

}  // namespace

std::string_view to_string(CrossComp v) {
  return name_from(kCrossComp, v);
}
bool parse(std::string_view name, CrossComp& out) {
  return parse_from(kCrossComp, name, out);
}
std::string_view to_string(StepEq v) {
  return name_from(kStepEq, v);
}
bool parse(std::string_view name, StepEq& out) {
  return parse_from(kStepEq, name, out);
}
std::string_view to_string(MpccMode v) {
  return name_from(kMpccMode, v);
}
bool parse(std::string_view name, MpccMode& out) {
  return parse_from(kMpccMode, name, out);
}
std::string_view to_string(StageLambdaSign v) {
  return name_from(kStageLambdaSign, v);
}
bool parse(std::string_view name, StageLambdaSign& out) {
  return parse_from(kStageLambdaSign, name, out);
}

std::vector<std::string> validate(const DiscretizationOptions& o) {
  std::vector<std::string> e;
  const int min_s =
      (o.rk_scheme == RkScheme::LobattoIIIA || o.rk_scheme == RkScheme::LobattoIIIC) ? 2 : 1;
  const int max_s = o.rk_scheme == RkScheme::ExplicitRK ? 4 : 9;
  require(e, o.n_s >= min_s && o.n_s <= max_s,
          fmt::format("discretization.n_s = {}: must be in {}..{} for {}", o.n_s, min_s, max_s,
                      to_string(o.rk_scheme)));
  require(e, o.N_FE >= 1 && o.N_FE <= 1000,
          fmt::format("discretization.N_finite_elements = {}: must be in 1..1000", o.N_FE));
  require(e, !o.use_fesd || o.N_FE >= 2,
          fmt::format("discretization.N_finite_elements = {}: FESD needs >= 2 finite elements "
                      "(with one there is no step size to move); use 2 or use_fesd = false",
                      o.N_FE));
  require(e, std::isfinite(o.gamma_h) && o.gamma_h > 0 && o.gamma_h <= 1,
          fmt::format("discretization.gamma_h = {}: must be in (0, 1]", o.gamma_h));
  require(e, finite_positive(o.rho_h),
          fmt::format("discretization.rho_h = {}: must be > 0", o.rho_h));
  return e;
}

std::vector<std::string> validate(const HomotopyOptions& o) {
  std::vector<std::string> e;
  require(e, finite_positive(o.sigma_0),
          fmt::format("homotopy.sigma_0 = {}: must be > 0", o.sigma_0));
  require(e,
          std::isfinite(o.homotopy_update_slope) && o.homotopy_update_slope > 0 &&
              o.homotopy_update_slope < 1,
          fmt::format("homotopy.homotopy_update_slope = {}: must be in (0, 1)",
                      o.homotopy_update_slope));
  require(e, finite_positive(o.sigma_N),
          fmt::format("homotopy.sigma_N = {}: must be > 0", o.sigma_N));
  require(e, !(finite_positive(o.sigma_N) && finite_positive(o.sigma_0)) || o.sigma_N <= o.sigma_0,
          fmt::format("homotopy.sigma_N = {}: must be <= sigma_0 = {}", o.sigma_N, o.sigma_0));
  require(e, finite_positive(o.complementarity_tol),
          fmt::format("homotopy.complementarity_tol = {}: must be > 0", o.complementarity_tol));
  require(e, std::isfinite(o.intermediate_tol) && o.intermediate_tol >= 0,
          fmt::format("homotopy.intermediate_tol = {}: must be >= 0 (0: ipopt.tol everywhere)",
                      o.intermediate_tol));
  require(e, o.max_homotopy_steps >= 0 && o.max_homotopy_steps <= 1000,
          fmt::format("homotopy.N_homotopy = {}: must be in 0..1000 (0: automatic)",
                      o.max_homotopy_steps));
  return e;
}

std::vector<std::string> validate(const NlpOptions& o) {
  std::vector<std::string> e;
  require(e, finite_positive(o.tol), fmt::format("ipopt.tol = {}: must be > 0", o.tol));
  require(e, finite_positive(o.acceptable_tol),
          fmt::format("ipopt.acceptable_tol = {}: must be > 0", o.acceptable_tol));
  require(e, o.max_iter >= 1, fmt::format("ipopt.max_iter = {}: must be >= 1", o.max_iter));
  require(e, o.print_level >= 0 && o.print_level <= 12,
          fmt::format("ipopt.print_level = {}: must be in 0..12", o.print_level));
  return e;
}

std::vector<std::string> validate(const IntegratorOptions& o) {
  std::vector<std::string> e = validate(o.discretization);
  for (auto& s : validate(o.homotopy)) e.push_back(std::move(s));
  for (auto& s : validate(o.nlp)) e.push_back(std::move(s));
  return e;
}

void check(const IntegratorOptions& o) {
  const auto errors = validate(o);
  if (errors.empty()) return;
  std::string msg = errors.front();
  for (std::size_t i = 1; i < errors.size(); ++i) msg += "; " + errors[i];
  throw InvalidOption(msg);
}

}  // namespace fesd
