// tests/ocp/ocp_input_test.cpp: fesd::solve checks an Ocp with the rules and messages of the
// problem-file loader (src/ocp/ocp_input.cpp, written once), before computing anything.
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>

namespace fesd {
namespace {

OcpProblem sensitivity() {
  return load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/ocp_sensitivity.toml");
}

template <class E>
void expect_solve_throws(const std::function<void(OcpProblem&)>& edit, const std::string& part) {
  OcpProblem q = sensitivity();
  edit(q);
  try {
    solve(q.ocp, q.options);
    ADD_FAILURE() << "no exception; expected one with '" << part << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(OcpInput, OptionRulesAreTheFileRules) {
  expect_solve_throws<InvalidOption>([](OcpProblem& q) { q.ocp.T = -1; },
                                     "ocp.T = -1: must be > 0");
  expect_solve_throws<InvalidOption>([](OcpProblem& q) { q.ocp.N_stages = 0; },
                                     "ocp.N_stages = 0: must be >= 1");
  expect_solve_throws<InvalidOption>([](OcpProblem& q) { q.ocp.rho_terminal = 0; },
                                     "ocp.rho_terminal = 0: must be > 0");
  expect_solve_throws<InvalidOption>(
      [](OcpProblem& q) { q.ocp.terminal_constraint = TerminalConstraint::L1; },
      "ocp.relax_terminal_constraint = ell_1: there are no terminal constraints to relax");
  expect_solve_throws<InvalidOption>(
      [](OcpProblem& q) {
        q.ocp.N_stages = 2;
        q.ocp.N_FE = {3, 3, 3};
      },
      "discretization.N_finite_elements = [3, 3, 3]: wrong length (expected 2 entries");
  expect_solve_throws<InvalidOption>(
      [](OcpProblem& q) {
        q.ocp.N_stages = 2;
        q.ocp.N_FE = {3, 1};
      },
      "discretization.N_finite_elements[1] = 1: FESD needs >= 2 finite elements");
  expect_solve_throws<InvalidOption>([](OcpProblem& q) { q.options.homotopy.sigma_0 = -1; },
                                     "homotopy.sigma_0 = -1: must be > 0");
}

TEST(OcpInput, DataRulesAreTheFileRules) {
  expect_solve_throws<InvalidModel>(
      [](OcpProblem& q) {
        q.ocp.lbx = Eigen::VectorXd::Constant(1, 3.0);
        q.ocp.ubx = Eigen::VectorXd::Constant(1, 2.0);
      },
      "ocp.lbx[0] = 3 > ocp.ubx[0] = 2: empty bounds (expected lbx <= ubx)");
  expect_solve_throws<InvalidModel>(
      [](OcpProblem& q) {
        q.ocp.lbx0 = Eigen::VectorXd::Constant(1, -1.0);
        q.ocp.ubx0 = Eigen::VectorXd::Constant(1, 0.0);
        q.ocp.x0 = Eigen::VectorXd::Constant(1, 0.5);
      },
      "model.x0[0]: 0.5 is outside [lbx0, ubx0] = [-1, 0]");
  expect_solve_throws<InvalidModel>(
      [](OcpProblem& q) { q.ocp.x0 = Eigen::VectorXd::Zero(2); },
      "model.x0: wrong length (expected 1 number, one per state, got 2)");
}

}  // namespace
}  // namespace fesd
