// The formatters of include/fesd/summary.hpp: the one place where homotopy rows, switches, step
// progress and the work/time split are turned into text.
#include "fesd/summary.hpp"

#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace fesd {

std::string format_switch(const SwitchEvent& s) {
  return fmt::format("    t_s = {:.12g}   active regions {{{}}} -> {{{}}}{}\n", s.t,
                     fmt::join(s.before, ","), fmt::join(s.after, ","),
                     s.located ? "" : "   (not located: may be off by up to one element)");
}

std::string homotopy_table_header() {
  return fmt::format("{:>4} {:>9} {:>10} {:>14} {:>9} {:>5}  {:<26} {:>8}\n", "k", "sigma", "comp",
                     "objective", "inf_pr", "iter", "IPOPT status", "time s");
}

std::string format_homotopy_row(const HomotopyRow& r) {
  std::string row = fmt::format(
      "{:>4} {:>9.1e} {:>10.2e} {:>14.7e} {:>9.1e} {:>5}  {:<26} {:>8.3f}", r.k, r.sigma,
      r.comp_residual, r.objective, r.inf_pr, r.nlp_iterations, r.nlp_status, r.wall_s);
  if (r.active_set_fixed)
    row += r.pinned_exits > 0
               ? fmt::format("  (the last NLP again, active set fixed, {} sliding exit{} pinned)",
                             r.pinned_exits, r.pinned_exits == 1 ? "" : "s")
               : std::string("  (the last NLP again, active set fixed)");
  if (r.retried) row += "  (failed: retried from the last converged NLP, smaller sigma step)";
  if (r.stalled) row += "  (residual stalled: a stationary point of the penalty)";
  if (r.restarted) row += "  (path replaced by the cold restart)";
  // (The live table has printed the replaced rows before the restart was known: this row says
  // which they are.)
  if (r.cold_start)
    row +=
        "  (cold restart from the initial guess; replaces the rows from the first failure without "
        "a retry left, or the stall)";
  return row + "\n";
}

std::string format_nlp_progress(const NlpProgress& p) {
  return fmt::format(
      "       ... IPOPT iteration {}{}, objective {:.7e}, inf_pr {:.1e}, inf_du {:.1e}, mu {:.1e}, "
      "{:.0f} s\n",
      p.iteration, p.run > 1 ? fmt::format(", run {}", p.run) : std::string(), p.objective,
      p.inf_pr, p.inf_du, p.mu, p.wall_s);
}

std::string format_step_progress(const StepProgress& p) {
  const std::string head =
      fmt::format("{}  step {:>4}/{}  t = {:<10.6g}  ",
                  p.run > 0 ? fmt::format("  run {}", p.run) : "", p.step, p.N_sim, p.t);
  if (p.active_set_path)
    return head + fmt::format("Newton {:>3}  (active set)       {}\n", p.newton_iterations,
                              to_string(p.status));
  return head + fmt::format("NLPs {:>2}  iter {:>4}  comp {:.1e}  {}\n", p.nlps, p.nlp_iterations,
                            p.comp_residual, to_string(p.status));
}

std::string format_warnings(const Summary& s) {
  std::string out;
  for (const std::string& w : s.warnings) out += fmt::format("  warning: {}\n", w);
  return out;
}

std::string format_work(const Summary& s, double per_step) {
  std::string out;
  auto per = [&](double v, const char* unit) {
    return per_step > 0 ? fmt::format("  ({:.1f} per {})", v / per_step, unit) : std::string();
  };
  if (s.active_set_path_steps > 0)
    out += fmt::format(
        "  active-set steps     {}  ({} by the homotopy; {} Newton iterations{}, {} LU "
        "factorizations, {:.3f} s)\n",
        s.active_set_path_steps, s.homotopy_path_steps, s.newton_iterations,
        per(s.newton_iterations, "step"), s.newton_factorizations, s.active_set_s);
  // Every step by Newton: no NLP, nothing to say about IPOPT.
  const bool nlps = s.homotopy_steps > 0 || s.active_set_path_steps == 0;
  if (nlps) {
    out += fmt::format("  NLPs solved          {}{}\n", s.homotopy_steps,
                       per(s.homotopy_steps, "step"));
    out += fmt::format("  IPOPT iterations     {}{}\n", s.nlp_iterations,
                       per(s.nlp_iterations, "step"));
    out += fmt::format("  max comp. residual   {:.2e}\n", s.max_comp_residual);
  }
  if (s.fallback_steps > 0)
    out += fmt::format("  retried steps        {}  (sparse cross complementarity (28))\n",
                       s.fallback_steps);
  if (s.refined_steps > 0)
    out += fmt::format("  refined steps        {}  (solved again with 2 N_FE elements)\n",
                       s.refined_steps);
  if (s.split_steps > 0)
    out += fmt::format("  split steps          {}  (retried as two half steps)\n", s.split_steps);
  if (s.active_set_solves > 0 || s.active_set_failures > 0)
    out += fmt::format("  fixed active set     {} re-solve{}  ({} failed: relaxed solution kept)\n",
                       s.active_set_solves, s.active_set_solves == 1 ? "" : "s",
                       s.active_set_failures + s.pin_failures);
  if (s.rescued_steps > 0)
    out += fmt::format(
        "  rescued steps        {}  (complementarity_tol missed, met by the fixed active set)\n",
        s.rescued_steps);
  if (s.pinned_exits > 0 || s.pin_failures > 0)
    out += fmt::format("  pinned sliding exits {}  ({} re-solve{} failed, unpinned)\n",
                       s.pinned_exits, s.pin_failures, s.pin_failures == 1 ? "" : "s");
  if (s.grid_moves > 0 || s.held_switches > 0)
    out += fmt::format("  grid moves           {}  ({} switch{} still held by an h bound)\n",
                       s.grid_moves, s.held_switches, s.held_switches == 1 ? "" : "es");
  if (s.allocation_solves > 0)
    out +=
        fmt::format("  allocation moves     {}  ({} re-solve{} of the allocation search)\n",
                    s.allocation_moves, s.allocation_solves, s.allocation_solves == 1 ? "" : "s");
  if (s.born_switches > 0)
    out += fmt::format("  born switches        {}  (probed at a touch of a switching surface)\n",
                       s.born_switches);
  out += fmt::format("  wall time            {:.3f} s", s.wall_s);
  out += per_step > 0 ? fmt::format("  ({:.2f} ms per step)\n", 1e3 * s.wall_s / per_step) : "\n";
  if (!nlps) return out;
  const double busy = s.derivative_s + s.solver_s;
  out += fmt::format("    derivatives        {:.3f} s  ({:.0f} %)\n", s.derivative_s,
                     busy > 0 ? 100 * s.derivative_s / busy : 0.0);
  out += fmt::format("    IPOPT + KKT solve  {:.3f} s  ({:.0f} %)\n", s.solver_s,
                     busy > 0 ? 100 * s.solver_s / busy : 0.0);
  out += fmt::format("    setup              {:.3f} s\n", s.setup_s);
  return out;
}

}  // namespace fesd
