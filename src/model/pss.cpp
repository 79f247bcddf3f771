// Pss: structure checks, default sign matrices (Sect. 2.2.1) and region bookkeeping.
#include <set>
#include <string>

#include <fmt/format.h>

#include "fesd/error.hpp"
#include "fesd/model.hpp"

namespace fesd {

int Subsystem::n_f() const {
  if (n_g > 0) return n_g;
  if (S.size() > 0) return static_cast<int>(S.rows());
  return n_c > 0 && n_c < 31 ? (1 << n_c) : 0;
}

Eigen::MatrixXd all_sign_rows(int n_c) {
  const int rows = 1 << n_c;
  Eigen::MatrixXd S(rows, n_c);
  for (int r = 0; r < rows; ++r)
    for (int j = 0; j < n_c; ++j) S(r, j) = ((r >> (n_c - 1 - j)) & 1) ? -1.0 : 1.0;
  return S;
}

Pss::Pss(PssDims dims, std::shared_ptr<const PssFunctions> functions)
    : dims_(std::move(dims)), functions_(std::move(functions)) {
  if (!functions_) throw InvalidModel("model: no functions given");
  if (dims_.n_x < 1) throw InvalidModel(fmt::format("model: n_x = {}: must be >= 1", dims_.n_x));
  if (dims_.n_u < 0) throw InvalidModel(fmt::format("model: n_u = {}: must be >= 0", dims_.n_u));
  if (dims_.n_p < 0) throw InvalidModel(fmt::format("model: n_p = {}: must be >= 0", dims_.n_p));
  if (dims_.subsystems.empty()) throw InvalidModel("model: no subsystem (regions) given");
  region_offset_.push_back(0);
  for (std::size_t k = 0; k < dims_.subsystems.size(); ++k) {
    const Subsystem& s = dims_.subsystems[k];
    const std::string where = fmt::format("model: subsystem {}", k);
    if ((s.n_c > 0) == (s.n_g > 0))
      throw InvalidModel(where + ": give either switching functions (n_c > 0) or indicator "
                                 "functions (n_g > 0), not both or neither");
    Eigen::MatrixXd S;
    if (s.n_c > 0) {
      if (s.S.size() == 0) {
        if (s.n_c > 10)
          throw InvalidModel(fmt::format("{}: n_c = {} gives 2^{} regions; give a sign matrix S "
                                         "with the regions you need",
                                         where, s.n_c, s.n_c));
        S = all_sign_rows(s.n_c);
      } else {
        S = s.S;
        if (S.cols() != s.n_c)
          throw InvalidModel(fmt::format("{}: sign matrix S has {} columns, expected n_c = {}",
                                         where, S.cols(), s.n_c));
        std::set<std::vector<int>> seen;
        for (Eigen::Index r = 0; r < S.rows(); ++r) {
          std::vector<int> row;
          for (Eigen::Index j = 0; j < S.cols(); ++j) {
            if (S(r, j) != 1.0 && S(r, j) != -1.0)
              throw InvalidModel(fmt::format("{}: S[{}][{}] = {}: entries must be +1 or -1", where,
                                             r, j, S(r, j)));
            row.push_back(static_cast<int>(S(r, j)));
          }
          if (!seen.insert(row).second)
            throw InvalidModel(fmt::format("{}: row {} of S repeats an earlier row", where, r));
        }
        if (S.rows() < 1) throw InvalidModel(where + ": sign matrix S has no rows");
      }
      n_c_ += s.n_c;
    } else {
      n_g_ += s.n_g;
    }
    S_.push_back(S);
    const int n_f = s.n_c > 0 ? static_cast<int>(S.rows()) : s.n_g;
    region_offset_.push_back(region_offset_.back() + n_f);
  }
  n_theta_ = region_offset_.back();
  for (int i = 0; i < dims_.n_x; ++i) state_names.push_back(fmt::format("x{}", i + 1));
  for (int i = 0; i < dims_.n_u; ++i) control_names.push_back(fmt::format("u{}", i + 1));
  for (int i = 0; i < dims_.n_p; ++i) parameter_names.push_back(fmt::format("p{}", i + 1));
  p_default = Eigen::VectorXd::Zero(dims_.n_p);
}

}  // namespace fesd
