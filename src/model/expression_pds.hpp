// src/model/expression_pds.hpp: a projected dynamical system (include/fesd/pds.hpp) whose vector
// field f and constraints c are parsed math expressions (problem files with
// [model] kind = "projected", docs/pds.md). The symbol layout is that of ExpressionModel:
// [ x (n_x_slots), u, p ]; c must not read controls.
#pragma once
#include <vector>

#include "fesd/pds.hpp"
#include "model/expression.hpp"
#include "model/expression_model.hpp"

namespace fesd {

/// Builds the Pds; throws fesd::InvalidModel on size mismatches or a constraint reading a
/// control.
Pds make_expression_pds(PdsDims dims, ExpressionLayout layout, std::vector<expr::Expression> f,
                        std::vector<expr::Expression> c);

/// The parsed expressions of a Pss made by make_expression_pds (text() is the source), for
/// descriptions of the model (`fesd check`); both null for a model given in C++.
struct PdsExpressionView {
  const std::vector<expr::Expression>* f = nullptr;
  const std::vector<expr::Expression>* c = nullptr;
};
PdsExpressionView expressions_of(const Pds& model);

}  // namespace fesd
