// src/integrator/sensitivity.hpp: sensitivities of one integration step by the implicit function
// theorem on its converged square system (docs/sensitivities.md).
//
// With the active set of every finite element (FESD) or every stage (the standard method) fixed,
// the equations of a step are a square system F(w; s0, q, p) = 0 in its free variables w (Thm 15
// of papers/fesd-filippov.txt). At a regular solution, dw/d(s0, q, p) = -F_w^{-1} F_(s0, q, p);
// the rows of the state at the step end give the step's map S = dx_end/ds0 and dx_end/dq,
// dx_end/dp. The integrator chains them over the steps (Thm 19's product of interval
// sensitivities).
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/tableau.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::integrator {

/// d x_end / d s0 (n_x x n_x), d x_end / dq (n_x x n_u), d x_end / dp (n_x x n_p) of one step.
struct StepSensitivity {
  Eigen::MatrixXd x0, u, p;
};

/// The square system of one step with a given set of free variables: the rows of the BlockNlp
/// (g(w) = g_lb, all equalities) and rows w[a] - w[b] = 0 (equal element lengths).
class SquareSystem {
 public:
  SquareSystem(const nlp::BlockNlp& nlp, std::vector<int> free,
               std::vector<std::pair<int, int>> equal);
  bool square() const;
  /// Newton's method from w (the fixed variables as given in w); false with `why` if it does not
  /// converge (||F||_inf <= 1e-12 max(1, ||w||_inf)) within max_it iterations.
  bool newton(std::vector<double>& w, int max_it, std::string& why);
  /// At a solution w: d w[x_end] / d w[inputs] = -(F_w^{-1} F_inputs) restricted to the rows
  /// x_end. False with `why` if the system is not square or F_w is singular.
  bool ift(const std::vector<double>& w, const std::vector<int>& inputs,
           const std::vector<int>& x_end, Eigen::MatrixXd& out, std::string& why);

 private:
  bool factor(const std::vector<double>& w, std::string& why);
  const nlp::BlockNlp& nlp_;
  std::vector<int> free_, col_of_;
  std::vector<std::pair<int, int>> equal_;
  Eigen::MatrixXd J_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  std::vector<double> g_, jac_;
};

/// Splits the columns of `d` (inputs s0, q, p in that order) into a StepSensitivity.
StepSensitivity split_inputs(const Eigen::MatrixXd& d, int n_x, int n_u, int n_p);

/// The standard method's step (use_fesd = false: h_n fixed) as a square system: per stage the
/// active set of the solution (theta_r > |lambda_r|: lambda_r = 0, else theta_r = 0), Newton
/// polish, then the IFT.
class StandardStepSensitivity {
 public:
  StandardStepSensitivity(const Pss& model, const Tableau& tab, const DiscretizationOptions& d,
                          double T_step, const Eigen::VectorXd& u, const Eigen::VectorXd& p);
  /// The sensitivity of the step from x0 whose solution is w_other (layout of `other`, an
  /// interval with the same options); false with `why` if not available.
  bool compute(const Eigen::VectorXd& x0, const discretization::FesdInterval& other,
               const std::vector<double>& w_other, StepSensitivity& out, std::string& why);

 private:
  const Pss& model_;
  Tableau tab_;
  DiscretizationOptions d_;
  nlp::BlockNlp nlp_;
  discretization::IntervalInputs in_;
  std::unique_ptr<discretization::FesdInterval> iv_;
};

/// Copies the values of an interval's variables (h, stage values, element ends, boundary LPs) at
/// w_from (layout `from`) into w_to (layout `to`); the two intervals have the same model, scheme
/// and N_FE.
void copy_interval(const Pss& model, const discretization::FesdInterval& from,
                   const std::vector<double>& w_from, const discretization::FesdInterval& to,
                   std::vector<double>& w_to);

}  // namespace fesd::integrator
