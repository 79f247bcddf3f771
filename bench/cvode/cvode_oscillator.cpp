// bench/cvode/cvode_oscillator.cpp: see cvode_oscillator.hpp.
#include "cvode_oscillator.hpp"
#include "../bench_timing.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numbers>
#include <vector>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

namespace fesd_bench {
namespace {

using fesd_bench::cpu_now;
using fesd_bench::median;

constexpr double kOmega = 2.0 * std::numbers::pi;

/// Which field applies: inside the unit circle (c < 0) A1 = [[1, w], [-w, 1]], outside A2.
struct Field {
  bool inside = true;
};

int rhs(sunrealtype, N_Vector y, N_Vector ydot, void* data) {
  const double w = static_cast<Field*>(data)->inside ? kOmega : -kOmega;
  const double* x = N_VGetArrayPointer(y);
  double* d = N_VGetArrayPointer(ydot);
  d[0] = x[0] + w * x[1];
  d[1] = -w * x[0] + x[1];
  return 0;
}

int jac(sunrealtype, N_Vector, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector, N_Vector) {
  const double w = static_cast<Field*>(data)->inside ? kOmega : -kOmega;
  SM_ELEMENT_D(J, 0, 0) = 1.0;
  SM_ELEMENT_D(J, 0, 1) = w;
  SM_ELEMENT_D(J, 1, 0) = -w;
  SM_ELEMENT_D(J, 1, 1) = 1.0;
  return 0;
}

int root(sunrealtype, N_Vector y, sunrealtype* g, void*) {
  const double* x = N_VGetArrayPointer(y);
  g[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
  return 0;
}

}  // namespace

CvodeRun cvode_oscillator(double rtol, double atol, bool bdf, int repeat) {
  CvodeRun out;
  out.rtol = rtol;
  out.atol = atol;
  out.bdf = bdf;
  const double T = std::numbers::pi / 2;
  const double x_exact[2] = {-1.5974603774506984, -0.7614936206060108};  // REFERENCE.md
  std::vector<double> setup, solve;
  for (int k = 0; k < repeat; ++k) {
    const double c0 = cpu_now();
    SUNContext ctx = nullptr;
    if (SUNContext_Create(nullptr, &ctx) != 0) return out;
    N_Vector y = N_VNew_Serial(2, ctx);
    N_VGetArrayPointer(y)[0] = std::exp(-1.0);
    N_VGetArrayPointer(y)[1] = 0.0;
    Field field;
    void* mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx);
    SUNMatrix A = nullptr;
    SUNLinearSolver LS = nullptr;
    SUNNonlinearSolver NLS = nullptr;
    bool ok = mem != nullptr && CVodeInit(mem, rhs, 0.0, y) == CV_SUCCESS &&
              CVodeSStolerances(mem, rtol, atol) == CV_SUCCESS &&
              CVodeSetUserData(mem, &field) == CV_SUCCESS &&
              CVodeRootInit(mem, 1, root) == CV_SUCCESS &&
              CVodeSetMaxNumSteps(mem, 100000) == CV_SUCCESS;
    if (ok && bdf) {
      A = SUNDenseMatrix(2, 2, ctx);
      LS = SUNLinSol_Dense(y, A, ctx);
      ok = CVodeSetLinearSolver(mem, LS, A) == CV_SUCCESS && CVodeSetJacFn(mem, jac) == CV_SUCCESS;
    } else if (ok) {
      NLS = SUNNonlinSol_FixedPoint(y, 0, ctx);
      ok = CVodeSetNonlinearSolver(mem, NLS) == CV_SUCCESS;
    }
    const double c1 = cpu_now();
    double t = 0, t_s = NAN;
    long steps = 0, rhs_evals = 0, root_evals = 0;
    while (ok && t < T) {
      const int flag = CVode(mem, T, y, &t, CV_NORMAL);
      long n = 0;
      CVodeGetNumSteps(mem, &n);
      steps += n;
      CVodeGetNumRhsEvals(mem, &n);
      rhs_evals += n;
      CVodeGetNumGEvals(mem, &n);
      root_evals += n;
      if (flag == CV_ROOT_RETURN) {
        // The crossing: the other field from here on, a fresh start of the multistep method.
        t_s = t;
        field.inside = !field.inside;
        ok = CVodeReInit(mem, t, y) == CV_SUCCESS;
      } else {
        ok = flag == CV_SUCCESS;
        break;
      }
    }
    const double c2 = cpu_now();
    if (ok) {
      const double* x = N_VGetArrayPointer(y);
      out.error_x = std::hypot(x[0] - x_exact[0], x[1] - x_exact[1]);
      out.error_t_s = std::abs(t_s - 1.0);
      out.steps = steps;
      out.rhs_evals = rhs_evals;
      out.root_evals = root_evals;
    }
    out.ok = ok;
    CVodeFree(&mem);
    if (NLS) SUNNonlinSolFree(NLS);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    N_VDestroy(y);
    SUNContext_Free(&ctx);
    if (!ok) return out;
    setup.push_back(c1 - c0);
    solve.push_back(c2 - c1);
  }
  out.setup_s = median(setup);
  out.solve_s = median(solve);
  return out;
}

}  // namespace fesd_bench
