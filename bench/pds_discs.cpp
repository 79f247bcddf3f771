// The collaborative manipulation OCP of papers/fesd-pds.txt Sect. IV-B (docs/pds.md, "Optimal
// control"): solves it and prints objective, complementarity, work and the smallest disc gap over
// all stage points; with --csv FILE writes t and x at every stage point (for the frames of
// docs/img/pds_discs.png, scripts/plot_pds_discs.py).
//
//   pds_discs [--N_stages 20] [--N_FE 3] [--no-h-penalty] [--csv FILE]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "pds_discs_model.hpp"

int main(int argc, char** argv) {
  int N_stages = 20, N_FE = 3;
  bool h_penalty = true;
  std::string csv;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--N_stages") && i + 1 < argc)
      N_stages = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--N_FE") && i + 1 < argc)
      N_FE = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-h-penalty"))
      h_penalty = false;
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc)
      csv = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: pds_discs [--N_stages N] [--N_FE N] [--no-h-penalty] [--csv FILE]\n");
      return 2;
    }
  }
  fesd::PdsOcp ocp = pds_discs::ocp(N_stages);
  ocp.pds.h_penalty = h_penalty;
  fesd::OcpOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  o.discretization.n_s = 2;
  o.discretization.N_FE = N_FE;
  o.constraints_at_stages = true;
  const fesd::OcpResult r = fesd::solve(ocp, o);
  double gap = pds_discs::min_gap(r.x.front());
  for (const auto& x : r.x_stage) gap = std::min(gap, pds_discs::min_gap(x));
  std::printf("%s\n", r.full_report(true).c_str());
  std::printf(
      "N_stages %d N_FE %d: status %s objective %.10g comp %.2e NLPs %d IPOPT iterations %d "
      "wall %.2f s min gap %.3e switches %zu\n",
      N_stages, N_FE, std::string(fesd::to_string(r.status)).c_str(), r.objective, r.comp_residual,
      r.summary.homotopy_steps, r.summary.nlp_iterations, r.summary.wall_s, gap, r.switches.size());
  std::printf("x(T) =");
  for (int i = 0; i < 6; ++i) std::printf(" %.6g", r.x.back()[i]);
  std::printf("\n");
  if (!csv.empty()) {
    FILE* f = std::fopen(csv.c_str(), "w");
    if (!f) return 3;
    std::fprintf(f, "t,x1,y1,x2,y2,x3,y3\n");
    std::fprintf(f, "0");
    for (int i = 0; i < 6; ++i) std::fprintf(f, ",%.10g", r.x.front()[i]);
    std::fprintf(f, "\n");
    for (std::size_t k = 0; k < r.t_stage.size(); ++k) {
      std::fprintf(f, "%.10g", r.t_stage[k]);
      for (int i = 0; i < 6; ++i) std::fprintf(f, ",%.10g", r.x_stage[k][i]);
      std::fprintf(f, "\n");
    }
    std::fclose(f);
  }
  return r.status == fesd::Status::Success ? 0 : 1;
}
