// Enum names and option validation. Each enum has one name table, indexed by its values, behind
// to_string, parse, the problem-file reader and the command line. validate() checks the ranges and
// rules of the option registry (option_registry.cpp).
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/option_registry.hpp"
#include "fesd/error.hpp"
#include "fesd/ocp.hpp"
#include "fesd/options.hpp"

namespace fesd {
namespace {

constexpr std::array<std::string_view, 5> kRkScheme{"radau_iia", "gauss_legendre", "lobatto_iiia",
                                                    "lobatto_iiic", "explicit_rk"};
constexpr std::array<std::string_view, 4> kCrossComp{"sparse", "stage_sum", "element", "neighbor"};
constexpr std::array<std::string_view, 6> kStepEq{
    "none", "eta", "eta_tanh", "heuristic_mean", "heuristic_delta", "l2_relaxed"};
constexpr std::array<std::string_view, 3> kStageLambdaSign{"all", "boundary", "auto"};
constexpr std::array<std::string_view, 6> kMpccMode{"scholtes_ineq",      "scholtes_eq",
                                                    "fischer_burmeister", "ell_1_penalty",
                                                    "elastic_ineq",       "elastic_two_sided"};
// nosnoc's relax_terminal_constraint values that fesd implements.
constexpr std::array<std::string_view, 2> kTerminalConstraint{"none", "ell_1"};
constexpr std::array<std::string_view, 3> kOcpInitialization{"constant", "simulation", "external"};
constexpr std::array<std::string_view, 4> kKktSolver{"auto", "sparse_ldl", "dense", "mumps"};
constexpr std::array<std::string_view, 2> kKktScaling{"warm", "fresh"};
constexpr std::array<std::string_view, 2> kStepSolver{"homotopy", "active_set"};
constexpr std::array<std::string_view, 2> kDcsMode{"stewart", "step"};
constexpr std::array<std::string_view, 2> kHomotopyUpdateRule{"linear", "superlinear"};

template <class E, std::size_t K>
std::string_view name_of(const std::array<std::string_view, K>& names, E v) {
  const auto i = static_cast<std::size_t>(v);
  return i < K ? names[i] : std::string_view("unknown");
}
std::string upper(std::string_view s) {
  std::string u(s);
  for (char& ch : u) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return u;
}

/// The enum value named `name` in `names`; with `upper_too` also its upper-case spelling (nosnoc's
/// enum members: RADAU_IIA, SUPERLINEAR).
template <class E, std::size_t K>
bool parse_from(const std::array<std::string_view, K>& names, std::string_view name, E& out,
                bool upper_too = false) {
  for (std::size_t i = 0; i < K; ++i)
    if (names[i] == name || (upper_too && upper(names[i]) == name)) {
      out = static_cast<E>(i);
      return true;
    }
  return false;
}

}  // namespace

namespace registry {
template <>
std::span<const std::string_view> enum_names<RkScheme>() {
  return kRkScheme;
}
template <>
std::span<const std::string_view> enum_names<CrossComp>() {
  return kCrossComp;
}
template <>
std::span<const std::string_view> enum_names<StepEq>() {
  return kStepEq;
}
template <>
std::span<const std::string_view> enum_names<StageLambdaSign>() {
  return kStageLambdaSign;
}
template <>
std::span<const std::string_view> enum_names<MpccMode>() {
  return kMpccMode;
}
template <>
std::span<const std::string_view> enum_names<TerminalConstraint>() {
  return kTerminalConstraint;
}
template <>
std::span<const std::string_view> enum_names<OcpInitialization>() {
  return kOcpInitialization;
}
template <>
std::span<const std::string_view> enum_names<KktSolver>() {
  return kKktSolver;
}
template <>
std::span<const std::string_view> enum_names<KktScaling>() {
  return kKktScaling;
}
template <>
std::span<const std::string_view> enum_names<StepSolver>() {
  return kStepSolver;
}
template <>
std::span<const std::string_view> enum_names<DcsMode>() {
  return kDcsMode;
}
template <>
std::span<const std::string_view> enum_names<HomotopyUpdateRule>() {
  return kHomotopyUpdateRule;
}
}  // namespace registry

std::string_view to_string(DcsMode v) {
  return name_of(kDcsMode, v);
}
bool parse(std::string_view name, DcsMode& out) {
  // nosnoc's spellings (DcsMode.Stewart, DcsMode.Step) too.
  if (name == "Stewart") name = "stewart";
  if (name == "Step") name = "step";
  return parse_from(kDcsMode, name, out);
}

std::string_view to_string(RkScheme v) {
  return name_of(kRkScheme, v);
}
bool parse(std::string_view name, RkScheme& out) {
  return parse_from(kRkScheme, name, out, /*upper_too=*/true);  // nosnoc's RADAU_IIA, ...
}
std::string_view to_string(CrossComp v) {
  return name_of(kCrossComp, v);
}
bool parse(std::string_view name, CrossComp& out) {
  return parse_from(kCrossComp, name, out);
}
std::string_view to_string(StepEq v) {
  return name_of(kStepEq, v);
}
bool parse(std::string_view name, StepEq& out) {
  // nosnoc's spellings of the two modes that are the same penalty in fesd. nosnoc's L2_RELAXED,
  // L2_RELAXED_SCALED and DIRECT differ from l2_relaxed and eta (scaling, tanh), so not those.
  if (name == "HEURISTIC_MEAN") name = "heuristic_mean";
  if (name == "HEURISTIC_DELTA") name = "heuristic_delta";
  return parse_from(kStepEq, name, out);
}
std::string_view to_string(MpccMode v) {
  return name_of(kMpccMode, v);
}
bool parse(std::string_view name, MpccMode& out) {
  return parse_from(kMpccMode, name, out);
}
std::string_view to_string(StageLambdaSign v) {
  return name_of(kStageLambdaSign, v);
}
bool parse(std::string_view name, StageLambdaSign& out) {
  return parse_from(kStageLambdaSign, name, out);
}
std::string_view to_string(TerminalConstraint v) {
  return name_of(kTerminalConstraint, v);
}
bool parse(std::string_view name, TerminalConstraint& out) {
  return parse_from(kTerminalConstraint, name, out);
}
std::string_view to_string(OcpInitialization v) {
  return name_of(kOcpInitialization, v);
}
bool parse(std::string_view name, OcpInitialization& out) {
  return parse_from(kOcpInitialization, name, out);
}
std::string_view to_string(HomotopyUpdateRule v) {
  return name_of(kHomotopyUpdateRule, v);
}
bool parse(std::string_view name, HomotopyUpdateRule& out) {
  return parse_from(kHomotopyUpdateRule, name, out, /*upper_too=*/true);  // nosnoc's LINEAR, ...
}
std::string_view to_string(KktSolver v) {
  return name_of(kKktSolver, v);
}
bool parse(std::string_view name, KktSolver& out) {
  return parse_from(kKktSolver, name, out);
}
std::string_view to_string(KktScaling v) {
  return name_of(kKktScaling, v);
}
bool parse(std::string_view name, KktScaling& out) {
  return parse_from(kKktScaling, name, out);
}
std::string_view to_string(StepSolver v) {
  return name_of(kStepSolver, v);
}
bool parse(std::string_view name, StepSolver& out) {
  return parse_from(kStepSolver, name, out);
}

std::vector<std::string> validate(const DiscretizationOptions& o) {
  return registry::check(registry::Table::Discretization, registry::target_of(o));
}

std::vector<std::string> validate(const HomotopyOptions& o) {
  return registry::check(registry::Table::Homotopy, registry::target_of(o));
}

double next_sigma(const HomotopyOptions& o, double sigma) {
  double next = o.homotopy_update_slope * sigma;
  if (o.homotopy_update_rule == HomotopyUpdateRule::Superlinear)
    next = std::min(next, std::pow(sigma, o.homotopy_update_exponent));
  return std::max(next, o.sigma_N);
}

int homotopy_length(const HomotopyOptions& o) {
  if (o.max_homotopy_steps > 0) return o.max_homotopy_steps;
  // The linear rule's count, kept finite for a slope next to 1 (1e9 NLPs: beyond any run).
  const double linear =
      1 + std::ceil(std::log(o.sigma_N / o.sigma_0) / std::log(o.homotopy_update_slope) - 1e-9);
  const int n_linear = static_cast<int>(std::min(linear, 1e9));
  if (o.homotopy_update_rule == HomotopyUpdateRule::Linear) return n_linear;
  // Superlinear: the NLPs until sigma reaches sigma_N, as the homotopy takes them; never more
  // than the linear rule's (each step is at least as long).
  int n = 1;
  for (double sigma = o.sigma_0; sigma > o.sigma_N * (1 + 1e-9) && n < n_linear; ++n)
    sigma = next_sigma(o, sigma);
  return n;
}

double final_sigma(const HomotopyOptions& o) {
  // As the homotopy computes it.
  double sigma = o.sigma_0;
  for (int k = 1, n = homotopy_length(o); k < n; ++k) sigma = next_sigma(o, sigma);
  return sigma;
}

std::vector<std::string> warnings(const HomotopyOptions& o) {
  if (!validate(o).empty()) return {};  // invalid settings are errors, reported elsewhere
  const double last = final_sigma(o);
  // sigma_N = complementarity_tol is fine: 0.1^k by repeated products lands 1 ulp above it.
  if (last <= o.complementarity_tol * (1 + 1e-9)) return {};
  const bool too_few = last > o.sigma_N * (1 + 1e-9);
  const std::string why =
      too_few ? fmt::format("N_homotopy = {} NLPs take sigma from sigma_0 = {:g} only down to {:g}",
                            o.max_homotopy_steps, o.sigma_0, last)
              : fmt::format("sigma_N = {:g}", o.sigma_N);
  return {fmt::format(
      "homotopy: {}, above complementarity_tol = {:g}: the last NLP allows complementarity "
      "products up to sigma and meets the tolerance only by chance; {}",
      why, o.complementarity_tol,
      too_few ? "raise N_homotopy (0: automatic) or lower sigma_N"
              : "set sigma_N <= complementarity_tol")};
}

std::vector<std::string> validate(const NlpOptions& o) {
  std::vector<std::string> e = registry::check(registry::Table::Ipopt, registry::target_of(o));
  const bool user_linear_solver = registry::user_sets(o, "linear_solver");
  if (o.kkt_scaling != KktScaling::Warm &&
      (user_linear_solver || o.kkt_solver == KktSolver::Mumps || o.kkt_solver == KktSolver::Dense))
    e.push_back(fmt::format(
        "ipopt.kkt_scaling = {} applies to fesd's sparse LDL' (kkt_solver = auto or sparse_ldl), "
        "not to {}",
        to_string(o.kkt_scaling),
        user_linear_solver ? std::string("an IPOPT linear_solver")
                           : fmt::format("kkt_solver = {}", to_string(o.kkt_solver))));
  return e;
}

std::vector<std::string> validate(const DiscretizationOptions& d, const HomotopyOptions& h,
                                  const NlpOptions& n) {
  std::vector<std::string> e = validate(d);
  for (auto& s : validate(h)) e.push_back(std::move(s));
  for (auto& s : validate(n)) e.push_back(std::move(s));
  // A rule across tables: the smoothed C-function needs groups with a common factor (one
  // complementarity pair per group), which the element and neighbor forms (29) do not have.
  if (h.mpcc_mode == MpccMode::FischerBurmeister && d.use_fesd &&
      (d.cross_comp == CrossComp::Element || d.cross_comp == CrossComp::Neighbor))
    e.push_back(fmt::format(
        "homotopy.mpcc_mode = fischer_burmeister: needs discretization.cross_comp_mode sparse or "
        "stage_sum (got {}: its groups sum products of different theta and lambda, not one pair "
        "that a C-function can smooth)",
        to_string(d.cross_comp)));
  return e;
}

std::vector<std::string> validate(const IntegratorOptions& o) {
  std::vector<std::string> e = validate(o.discretization, o.homotopy, o.nlp);
  for (auto& s : registry::check(registry::Table::Simulation, registry::target_of(o)))
    e.push_back(std::move(s));
  return e;
}

void check(const IntegratorOptions& o) {
  const auto errors = validate(o);
  if (!errors.empty()) throw InvalidOption(registry::join(errors));
}

}  // namespace fesd
