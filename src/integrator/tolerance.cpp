// simulate(): the step count chosen for a target accuracy, and an error estimate for every
// simulation (include/fesd/integrator.hpp; the design and its measurements are in
// docs/formulation.md, "Accuracy by tolerance").
//
// Step doubling with Richardson extrapolation. FESD keeps the classical order p of its Runge-Kutta
// scheme through switches (Theorem 17), so runs with N and M steps differ by
//   x_N - x_M ~ e_N ((N / M)^p - 1),   e_N = x_N - x_exact ~ C (T / N)^p,
// and |x_N - x_M| / |(N / M)^p - 1| estimates |e_N|. Every estimate is the larger of two: the
// last pair's (e1) and the pair before it carried over to N at order p (e2). e1 alone fails when
// an element's length does not shrink with the step (the first element [0, t_s] of a switch at
// t_s < T / (2N) is the same in both runs, so its error cancels in x_N - x_M): the coarser pair
// still sees it. Runs whose switch lists differ (a coarse run that missed or invented a switch)
// are not compared at all.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/accuracy_options.hpp"
#include "core/limits.hpp"
#include "core/option_registry.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/pds.hpp"
#include "fesd/problem_file.hpp"

namespace fesd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The first step count of a search without N_sim: cheap, and fine enough that the doubling
/// sequence 10, 20, 40, ... reaches the asymptotic range of the examples in two or three runs.
constexpr int kFirstN = 10;
/// e1 and e2 agree within this factor: the runs converge at order p (docs/formulation.md).
constexpr double kConsistency = 8.0;
/// The next N_sim is N (estimate / tol)^(1/p) times this margin, between 2 N and 4 N.
constexpr double kSafety = 1.2;
constexpr int kMaxGrowth = 4;

using Clock = std::chrono::steady_clock;

struct Run {
  IntegratorResult result;
  int N_sim = 0;
  bool ok() const { return result.status == Status::Success; }
};

/// The same switches in the same order (regions before and after each).
bool same_switches(const IntegratorResult& a, const IntegratorResult& b) {
  if (a.switches.size() != b.switches.size()) return false;
  for (std::size_t i = 0; i < a.switches.size(); ++i)
    if (a.switches[i].before != b.switches[i].before || a.switches[i].after != b.switches[i].after)
      return false;
  return true;
}

/// |(N / M)^p - 1|: the factor between x_N - x_M and the error of x_N.
double pair_factor(int N, int M, int p) {
  return std::abs(std::pow(static_cast<double>(N) / M, p) - 1.0);
}

/// The error estimate of run N from run M (same switches): for x(T) and the switch times.
struct PairEstimate {
  double x = kNaN, t_s = kNaN;
};
PairEstimate pair_estimate(const Run& n, const Run& m, int p) {
  const double f = pair_factor(n.N_sim, m.N_sim, p);
  PairEstimate e;
  e.x = (n.result.x_final() - m.result.x_final()).norm() / f;
  if (!n.result.switches.empty()) {
    double d = 0;
    for (std::size_t i = 0; i < n.result.switches.size(); ++i)
      d = std::max(d, std::abs(n.result.switches[i].t - m.result.switches[i].t));
    e.t_s = d / f;
  }
  return e;
}

/// The scheme's classical order, or 1 for the standard method across switches (it places them on
/// its fixed grid: first order at best, docs/benchmarks.md).
int order_of(const IntegratorOptions& o, const IntegratorResult& r) {
  const DiscretizationOptions& d = o.discretization;
  if (!d.use_fesd && !r.switches.empty()) return 1;
  return make_tableau(d.rk_scheme, d.n_s).order;
}

/// The error of the NLP solutions themselves: IPOPT's tolerance, and where the active set is not
/// fixed after the homotopy (schemes that are not stiffly accurate, the standard method,
/// fix_active_set = false, or a failed re-solve) the relaxation's complementarity_tol.
double noise_floor(const IntegratorOptions& o, const IntegratorResult& r, double scale) {
  const DiscretizationOptions& d = o.discretization;
  const bool fixed = d.use_fesd && o.homotopy.fix_active_set &&
                     make_tableau(d.rk_scheme, d.n_s).stiffly_accurate &&
                     r.summary.active_set_failures == 0;
  const double floor = 10.0 * o.nlp.tol * std::max(1.0, scale);
  return fixed ? floor : std::max(floor, o.homotopy.complementarity_tol);
}

std::string list_N(const std::vector<int>& Ns) {
  std::string s;
  for (int N : Ns) s += fmt::format("{}{}", s.empty() ? "" : ", ", N);
  return s;
}

/// The two estimates of the result's error (NaN where unavailable), and why they are rough
/// (one sentence each; empty if they agree).
struct Estimates {
  PairEstimate e1, e2;
  std::vector<std::string> rough;
};

/// Fills `a` (estimate, switch times, consistency, note) for the result run r from its
/// companions c (the nearest, compared directly) and d (the pair c-d carried over to r at order
/// p); c or d null if unavailable.
Estimates estimate(Accuracy& a, const Run& r, const Run* c, const Run* d,
                   const IntegratorOptions& o) {
  a.order = order_of(o, r.result);
  const int p = a.order;
  a.noise_floor = noise_floor(o, r.result, r.result.x_final().norm());
  const double t_end = r.result.t.empty() ? 0.0 : r.result.t.back();
  const double floor_ts = noise_floor(o, r.result, std::abs(t_end));
  Estimates e;
  if (c == nullptr) {
    a.note = "no estimate: no companion run with the same switches succeeded";
    return e;
  }
  e.e1 = pair_estimate(r, *c, p);
  if (d != nullptr) {
    const PairEstimate cd = pair_estimate(*c, *d, p);
    const double carry = std::pow(static_cast<double>(c->N_sim) / r.N_sim, p);
    e.e2.x = cd.x * carry;
    e.e2.t_s = cd.t_s * carry;
  }
  const double x = std::isnan(e.e2.x) ? e.e1.x : std::max(e.e1.x, e.e2.x);
  a.at_noise_floor = x < a.noise_floor;
  a.error_estimate = std::max(x, a.noise_floor);
  if (!r.result.switches.empty()) {
    const double ts = std::isnan(e.e2.t_s) ? e.e1.t_s : std::max(e.e1.t_s, e.e2.t_s);
    // Switch times equal to round-off in every run while x(T) is not: an element between two
    // events that every run shares (the first element [t0, t_s] when t_s is shorter than every
    // step); their error cancels in the differences, so there is no estimate.
    if (ts >= floor_ts || a.at_noise_floor) a.switch_time_estimate = std::max(ts, floor_ts);
    if (!std::isnan(e.e2.t_s)) {
      const double big = std::max(std::max(e.e1.t_s, e.e2.t_s), floor_ts);
      const double small = std::max(std::min(e.e1.t_s, e.e2.t_s), floor_ts);
      a.switch_times_consistent = big <= kConsistency * small;
    }
  }
  std::vector<int> Ns{c->N_sim, r.N_sim};
  if (d != nullptr) Ns.insert(Ns.begin(), d->N_sim);
  std::sort(Ns.begin(), Ns.end());
  a.note = fmt::format("Richardson extrapolation at order {} from N_sim = {}", p, list_N(Ns));
  if (d == nullptr) {
    a.note += " (two runs: not checked against a third)";
    return e;
  }
  // Both estimates raised to the noise floor: differences of noise say nothing about the order.
  const double big = std::max(std::max(e.e1.x, e.e2.x), a.noise_floor);
  const double small = std::max(std::min(e.e1.x, e.e2.x), a.noise_floor);
  a.consistent = big <= kConsistency * small;
  if (a.at_noise_floor)
    a.note += fmt::format("; the runs agree to the NLP noise floor {:.1e}", a.noise_floor);
  else if (!a.consistent)
    e.rough.push_back(fmt::format(
        "the error estimate is rough: the last two pairs of runs give {:.1e} and {:.1e}, not "
        "within a factor {:g} (not yet converging at order {})",
        e.e1.x, e.e2.x, kConsistency, p));
  if (!r.result.switches.empty() && !a.switch_times_consistent && !std::isnan(e.e2.t_s))
    e.rough.push_back(fmt::format(
        "the switch time estimate is rough: the last two pairs of runs give {:.1e} and {:.1e} (a "
        "switch moves between the runs more than order {} predicts)",
        e.e1.t_s, e.e2.t_s, p));
  if (!r.result.switches.empty() && std::isnan(a.switch_time_estimate))
    a.note +=
        "; no switch time estimate: the runs give the same switch times to round-off while x(T) "
        "differs (an element that no run refines, such as [0, t_s] shorter than every step)";
  for (const std::string& why : e.rough) a.note += "; " + why;
  return e;
}

/// The runs' summary in the result: AccuracyRun per run, in the order made.
AccuracyRun info_of(const Run& r, double estimate, double wall_s) {
  AccuracyRun i;
  i.N_sim = r.N_sim;
  i.status = r.result.status;
  i.x_final = r.result.x_final();
  i.switch_times = r.result.switch_times();
  i.error_estimate = estimate;
  i.wall_s = wall_s;
  return i;
}

/// The companion runs of a given N_sim: about N / 2 and N / 4 (together 3/4 of its cost); below
/// 3 steps 2 N and 4 N.
std::pair<int, int> companions(int N) {
  if (N < 3) return {2 * N, 4 * N};
  const int c = (N + 1) / 2;
  return {c, (c + 1) / 2};
}

/// The largest N_sim whose step T_sim / N_sim is not below the smallest step (core::kMinStep).
int largest_N(double T_sim, int N_sim_max) {
  const double n = std::floor(T_sim / core::kMinStep);
  return n >= N_sim_max ? N_sim_max : std::max(1, static_cast<int>(n));
}

/// One run of the integrator with N_sim steps (that of a Pss or of a Pds).
using RunFn = std::function<IntegratorResult(int N_sim, const IntegratorOptions&)>;

class Simulation {
 public:
  Simulation(RunFn integrate_N, double T_sim, const AccuracyOptions& a, const IntegratorOptions& o)
      : integrate_(std::move(integrate_N)), T_sim_(T_sim), acc_(a), opt_(o) {
    // Progress of every run through the caller's callback, numbered.
    if (o.on_step) {
      opt_.on_step = [this, cb = o.on_step](const StepProgress& s) {
        StepProgress numbered = s;
        numbered.run = static_cast<int>(infos_.size()) + 1;
        cb(numbered);
      };
    }
  }

  /// N_sim given, no tol_sim: the run asked for and two companions.
  IntegratorResult given() {
    const int N = acc_.N_sim;
    Run r = run(N);
    report();
    if (!r.ok()) return finish(std::move(r), 0, "no estimate: the run failed");
    if (!acc_.error_estimate)
      return finish(std::move(r), 0, "no estimate: error_estimate = false (one run at N_sim)");
    const auto [n_c, n_d] = companions(N);
    const Run c = run(n_c);
    report();
    const Run d = run(n_d);
    report();
    const Run* pc = c.ok() && same_switches(r.result, c.result) ? &c : nullptr;
    const Run* pd = d.ok() && same_switches(r.result, d.result) ? &d : nullptr;
    if (pc == nullptr) std::swap(pc, pd);  // compare with the one that matches
    Accuracy a;
    const Estimates e = estimate(a, r, pc, pd, opt_);
    if (pc == nullptr) {
      a.note = different_switches_note(r, {&c, &d});
      r.result.summary.warnings.push_back(a.note);
    }
    for (const std::string& why : e.rough) r.result.summary.warnings.push_back(why);
    infos_.front().error_estimate = a.error_estimate;
    return finish(std::move(r), std::move(a));
  }

  /// tol_sim: runs with growing N_sim until the estimate meets it with consistent runs.
  IntegratorResult search() {
    const double tol = acc_.tol_sim > 0 ? acc_.tol_sim : kDefaultTolSim;
    const int N_cap = largest_N(T_sim_, acc_.N_sim_max);
    int N = std::min(acc_.N_sim > 0 ? acc_.N_sim : kFirstN, N_cap);
    std::vector<Run> ok;  // the successful runs, N increasing
    Run last_failed;
    Accuracy a;
    Estimates e;
    for (;;) {
      Run r = run(N);
      if (r.ok()) {
        // The companions: the last successful runs, if their switches are the same.
        const Run* c =
            !ok.empty() && same_switches(r.result, ok.back().result) ? &ok.back() : nullptr;
        const Run* d =
            c != nullptr && ok.size() >= 2 && same_switches(r.result, ok[ok.size() - 2].result)
                ? &ok[ok.size() - 2]
                : nullptr;
        a = Accuracy{};
        e = estimate(a, r, c, d, opt_);
        if (c == nullptr && !ok.empty()) a.note = different_switches_note(r, {&ok.back()});
        infos_.back().error_estimate = a.error_estimate;
        report();
        ok.push_back(std::move(r));
        a.met = a.consistent && a.error_estimate <= tol;
        // A target below the noise floor: the runs cannot show more than that they agree to it.
        const bool floor_reached = a.consistent && a.at_noise_floor;
        if (a.met || floor_reached || N >= N_cap) break;
        int next = 2 * N;
        if (!std::isnan(a.error_estimate) && !a.at_noise_floor) {
          const double want = N * std::pow(a.error_estimate / tol, 1.0 / a.order) * kSafety;
          next = static_cast<int>(std::ceil(std::clamp(want, 2.0 * N, double(kMaxGrowth) * N)));
        }
        N = std::min(next, N_cap);
      } else {
        report();
        last_failed = std::move(r);
        if (N >= N_cap) break;
        N = std::min(2 * N, N_cap);  // a coarse run that fails: refine
      }
    }
    a.tol_sim = tol;
    if (ok.empty()) return finish(std::move(last_failed), tol, "no estimate: every run failed");
    Run best = std::move(ok.back());
    for (const std::string& why : e.rough) best.result.summary.warnings.push_back(why);
    if (a.met) return finish(std::move(best), std::move(a));
    // Not reached: the finest successful run, saying why.
    best.result.status = Status::ToleranceNotMet;
    if (a.consistent && a.at_noise_floor) {
      best.result.message = fmt::format(
          "tol_sim = {:g} is below the noise floor {:.1e} of the NLP solutions (10 ipopt.tol "
          "max(1, |x(T)|), or complementarity_tol where the active set is not fixed): the runs "
          "agree to that floor at N_sim = {}",
          tol, a.noise_floor, best.N_sim);
      return finish(std::move(best), std::move(a));
    }
    std::string why;
    if (std::isnan(a.error_estimate))
      why = a.note;
    else if (a.error_estimate > tol)
      why = fmt::format("the error estimate is {:.2e}", a.error_estimate);
    else
      why =
          fmt::format("the error estimate {:.2e} is not confirmed ({})", a.error_estimate, a.note);
    best.result.message = fmt::format(
        "tol_sim = {:g} not reached with N_sim up to {}{}: {} at N_sim = {}{}", tol, N_cap,
        N_cap == acc_.N_sim_max ? " (N_sim_max)" : " (the smallest step)", why, best.N_sim,
        last_failed.N_sim > best.N_sim
            ? fmt::format(" (the run at N_sim = {} failed: {})", last_failed.N_sim,
                          to_string(last_failed.result.status))
            : "");
    return finish(std::move(best), std::move(a));
  }

 private:
  Run run(int N) {
    const auto t0 = Clock::now();
    Run r{integrate_(N, opt_), N};
    infos_.push_back(info_of(r, kNaN, std::chrono::duration<double>(Clock::now() - t0).count()));
    return r;
  }

  /// "no estimate: the run at N_sim = 40 has 5 switches, the one at 20 has 3, ...".
  static std::string different_switches_note(const Run& r,
                                             std::initializer_list<const Run*> others) {
    const auto count = [](const Run& x) {
      const std::size_t n = x.result.switches.size();
      return fmt::format("{} switch{}", n, n == 1 ? "" : "es");
    };
    std::string s = fmt::format("no estimate: the run at N_sim = {} has {}", r.N_sim, count(r));
    bool differ = false;
    for (const Run* x : others) {
      if (x->N_sim == 0) continue;
      if (!x->ok()) {
        s += fmt::format(", the one at {} failed ({})", x->N_sim, to_string(x->result.status));
      } else if (same_switches(r.result, x->result)) {
        s += fmt::format(", the one at {} the same", x->N_sim);
      } else {
        s += fmt::format(", the one at {} {}", x->N_sim, count(*x));
        differ = true;
      }
    }
    return differ ? s + " (a run too coarse to resolve every switch; a larger N_sim helps)" : s;
  }

  void report() const {
    if (acc_.on_run) acc_.on_run(infos_.back());
  }

  IntegratorResult finish(Run r, double tol_sim, std::string note) {
    Accuracy a;
    a.tol_sim = tol_sim;
    a.note = std::move(note);
    return finish(std::move(r), std::move(a));
  }
  IntegratorResult finish(Run r, Accuracy a) {
    a.runs = std::move(infos_);
    a.N_sim = r.N_sim;
    r.result.accuracy = std::move(a);
    return std::move(r.result);
  }

  RunFn integrate_;
  double T_sim_;
  const AccuracyOptions& acc_;
  IntegratorOptions opt_;
  std::vector<AccuracyRun> infos_;
};

/// The runs of simulate() for either kind of model.
IntegratorResult simulate_runs(const RunFn& integrate_N, double T_sim,
                               const AccuracyOptions& accuracy, const IntegratorOptions& options) {
  if (const auto e =
          registry::validate_simulation(T_sim, accuracy.N_sim, accuracy.tol_sim, accuracy.N_sim_max,
                                        0.0, accuracy.error_estimate);
      !e.empty())
    throw InvalidOption(registry::join(e));
  Simulation s(integrate_N, T_sim, accuracy, options);
  if (accuracy.N_sim > 0 && accuracy.tol_sim == 0) return s.given();
  return s.search();
}

}  // namespace

IntegratorResult simulate(const Pss& model, const Eigen::VectorXd& x0, double T_sim,
                          const AccuracyOptions& accuracy, const IntegratorOptions& options,
                          const Eigen::VectorXd& u, const Eigen::VectorXd& p) {
  return simulate_runs(
      [&](int N, const IntegratorOptions& o) { return integrate(model, x0, T_sim, N, o, u, p); },
      T_sim, accuracy, options);
}

IntegratorResult simulate(const Pds& model, const Eigen::VectorXd& x0, double T_sim,
                          const AccuracyOptions& accuracy, const IntegratorOptions& options,
                          const Eigen::VectorXd& u, const Eigen::VectorXd& p,
                          const PdsOptions& pds) {
  return simulate_runs(
      [&](int N, const IntegratorOptions& o) {
        return integrate(model, x0, T_sim, N, o, u, p, pds);
      },
      T_sim, accuracy, options);
}

void shift_times(IntegratorResult& r, double t0) {
  if (t0 == 0.0) return;
  for (double& t : r.t) t += t0;
  for (double& t : r.t_stage) t += t0;
  for (SwitchEvent& s : r.switches) s.t += t0;
  for (AccuracyRun& run : r.accuracy.runs)
    for (double& t : run.switch_times) t += t0;
}

IntegratorResult simulate(const SimulationProblem& q,
                          const std::function<void(const AccuracyRun&)>& on_run) {
  AccuracyOptions a = accuracy_options(q);
  a.on_run = on_run;
  IntegratorResult r = simulate(q.model, q.x0, q.T_sim, a, q.options, q.u, q.p);
  shift_times(r, q.t0);
  return r;
}

std::string format_accuracy_rule(const AccuracyOptions& a, double T_sim) {
  if (a.N_sim > 0 && a.tol_sim == 0 && !a.error_estimate)
    return fmt::format("N_sim = {} (step {:g}); no error estimate (error_estimate = false)",
                       a.N_sim, T_sim / a.N_sim);
  if (a.N_sim > 0 && a.tol_sim == 0) {
    const auto [c, d] = companions(a.N_sim);
    return fmt::format(
        "N_sim = {} (step {:g}); error estimated from companion runs at N_sim = {} and {}", a.N_sim,
        T_sim / a.N_sim, c, d);
  }
  const int cap = largest_N(T_sim, a.N_sim_max);
  return fmt::format(
      "N_sim chosen for tol_sim = {:g}{}: runs from N_sim = {} up to {}{}, each error estimated "
      "from the runs before",
      a.tol_sim > 0 ? a.tol_sim : kDefaultTolSim, a.tol_sim > 0 ? "" : " (the default)",
      a.N_sim > 0 ? std::min(a.N_sim, cap) : std::min(kFirstN, cap), cap,
      cap == a.N_sim_max ? " (N_sim_max)" : " (the smallest step)");
}

std::string format_accuracy(const Accuracy& a) {
  if (a.runs.empty()) return {};
  std::string out;
  if (std::isnan(a.error_estimate)) {
    out += "  error estimate       none\n";
  } else {
    std::string target;
    if (a.tol_sim > 0)
      target = fmt::format("; tol_sim {:g} {}", a.tol_sim, a.met ? "met" : "NOT met");
    out += fmt::format("  error estimate       {}{:.1e}  (||x(T) - x_exact(T)||{})\n",
                       a.at_noise_floor ? "<= " : "", a.error_estimate, target);
  }
  if (!std::isnan(a.switch_time_estimate))
    out += fmt::format("  switch time estimate {:.1e}  (max |t_s - t_s,exact|{})\n",
                       a.switch_time_estimate, a.switch_times_consistent ? "" : "; rough");
  std::vector<int> Ns;
  double wall = 0;
  for (const AccuracyRun& r : a.runs) {
    Ns.push_back(r.N_sim);
    wall += r.wall_s;
  }
  out += fmt::format("  runs                 N_sim = {}  ({:.3f} s in all)\n", list_N(Ns), wall);
  out += fmt::format("  how                  {}\n", a.note);
  return out;
}

std::string format_accuracy_run(const AccuracyRun& r, double tol_sim) {
  std::string s = fmt::format("  run with N_sim = {}: {}", r.N_sim, to_string(r.status));
  if (!std::isnan(r.error_estimate)) {
    s += fmt::format(", error estimate {:.1e}", r.error_estimate);
    if (tol_sim > 0) s += fmt::format(" (tol_sim {:g})", tol_sim);
  }
  return s + fmt::format(", {:.2f} s\n", r.wall_s);
}

}  // namespace fesd
