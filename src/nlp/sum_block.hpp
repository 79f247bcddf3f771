// src/nlp/sum_block.hpp: the linear block c = sum_i w_i (optionally minus a lifted variable w_0),
// shared by the discretization (sum h_n = T, lifted sums of (31)) and the OCP (l1 slack penalty).
#pragma once

namespace fesd::nlp {

/// c[0] = sum_{i >= 0} w_i, or with `minus_first` c[0] = sum_{i >= 1} w_i - w_0 (a lifted sum
/// S = w_0 of the other inputs, imposed as c = 0).
struct Sum {
  int k = 0;
  bool minus_first = false;
  int num_inputs() const { return k; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (int i = minus_first ? 1 : 0; i < k; ++i) s = s + w[i];
    c[0] = minus_first ? s - w[0] : s;
  }
};

}  // namespace fesd::nlp
