// src/discretization/regrid.cpp: switches held by the grid, and moving the grid under them
// (FesdInterval::segment_boundaries, held_switches, regrid; docs/formulation.md, "Switches held
// by the grid").
#include <algorithm>
#include <cmath>
#include <numeric>

#include "discretization/fesd_interval.hpp"

namespace fesd::discretization {

std::vector<int> FesdInterval::segment_boundaries(const double* w) const {
  std::vector<int> all{0};
  std::vector<int> before = active_set(w, 0);
  for (int n = 1; n < N_FE_; ++n) {
    std::vector<int> now = active_set(w, n);
    if (now != before) all.push_back(n);
    before = std::move(now);
  }
  all.push_back(N_FE_);
  // Segments of length ~0 (elements collapsed at a switch, e.g. a crossing written as
  // {1} -> {0,1} -> {0} through an element of length 0) join the segment after them (the last
  // one the segment before): the switch is one event at one time.
  const double tol = held_tol();
  auto length = [&](int first, int end) {
    double s = 0;
    for (int n = first; n < end; ++n) s += w[h(n)];
    return s;
  };
  std::vector<int> b{0};
  for (std::size_t j = 1; j < all.size(); ++j) {
    const bool last = j + 1 == all.size();
    if (!last && length(b.back(), all[j]) <= tol) continue;  // joins the next segment
    if (last && b.size() > 1 && length(b.back(), all[j]) <= tol) b.pop_back();
    b.push_back(all[j]);
  }
  return b;
}

std::vector<int> FesdInterval::held_switches(const double* w) const {
  std::vector<int> held;
  if (!opt_.use_fesd) return held;
  const double h0 = in_.T / N_FE_, tol = held_tol();
  const double lb = (1.0 - opt_.gamma_h) * h0, ub = (1.0 + opt_.gamma_h) * h0;
  // Every element of [first, end) at a bound: all at the same one (the segment cannot grow, or
  // cannot shrink), or a mix, such as a collapsed element next to one at the upper bound, which
  // the step-equilibration penalty keeps from evening out.
  auto at_bound = [&](int first, int end) {
    for (int n = first; n < end; ++n)
      if (w[h(n)] > lb + tol && w[h(n)] < ub - tol) return false;
    return true;
  };
  const std::vector<int> b = segment_boundaries(w);
  for (std::size_t j = 1; j + 1 < b.size(); ++j)
    if (at_bound(b[j - 1], b[j]) || at_bound(b[j], b[j + 1])) held.push_back(b[j]);
  return held;
}

std::vector<double> FesdInterval::held_switch_times(const double* w, double t0) const {
  std::vector<double> times;
  for (int n : held_switches(w)) {
    double t = t0;
    for (int e = 0; e < n; ++e) t += w[h(e)];
    times.push_back(t);
  }
  return times;
}

namespace {

/// Lagrange interpolation through (tau_k, y_k) at tau, component i.
double lagrange(const std::vector<double>& tau, const std::vector<const double*>& y, int i,
                double t) {
  double s = 0;
  for (std::size_t k = 0; k < tau.size(); ++k) {
    double l = 1;
    for (std::size_t j = 0; j < tau.size(); ++j)
      if (j != k) l *= (t - tau[j]) / (tau[k] - tau[j]);
    s += l * y[k][i];
  }
  return s;
}

/// Elements per segment: proportional to the lengths (largest remainder), at least one each.
std::vector<int> apportion(const std::vector<double>& lengths, int N) {
  const std::size_t J = lengths.size();
  std::vector<int> n(J, 1);
  int left = N - static_cast<int>(J);
  // Give the remaining elements one at a time to the segment whose elements are longest.
  for (; left > 0; --left) {
    std::size_t best = 0;
    for (std::size_t j = 1; j < J; ++j)
      if (lengths[j] / n[j] > lengths[best] / n[best]) best = j;
    ++n[best];
  }
  return n;
}

}  // namespace

std::vector<int> FesdInterval::segment_counts(const double* w) const {
  const std::vector<int> b = segment_boundaries(w);
  std::vector<int> count(b.size() - 1);
  for (std::size_t j = 0; j + 1 < b.size(); ++j) count[j] = b[j + 1] - b[j];
  return count;
}

bool FesdInterval::regrid(const double* w_old, std::vector<double>& w_new) const {
  const std::vector<int> b = segment_boundaries(w_old);
  const std::size_t J = b.size() - 1;  // segments
  if (static_cast<int>(J) > N_FE_) return false;
  std::vector<double> lengths(J);
  for (std::size_t j = 0; j < J; ++j)
    for (int n = b[j]; n < b[j + 1]; ++n) lengths[j] += w_old[h(n)];
  const std::vector<int> count = apportion(lengths, N_FE_);
  const double h0 = in_.T / N_FE_;
  for (std::size_t j = 0; j < J; ++j) {  // the switches stay where they are
    const double hj = lengths[j] / count[j];
    if (hj < (1.0 - opt_.gamma_h) * h0 - held_tol() || hj > (1.0 + opt_.gamma_h) * h0 + held_tol())
      return false;
  }
  return regrid(w_old, w_new, count);
}

bool FesdInterval::regrid(const double* w_old, std::vector<double>& w_new,
                          const std::vector<int>& count) const {
  // (the step form keeps its grid: regridding copies Stewart's per-region multipliers)
  if (!opt_.use_fesd || step_) return false;
  const int n_x = model_.n_x(), n_th = model_.n_theta(), n_sys = model_.n_sys();
  const double h0 = in_.T / N_FE_;
  const double lb = (1.0 - opt_.gamma_h) * h0, ub = (1.0 + opt_.gamma_h) * h0;
  const std::vector<int> b = segment_boundaries(w_old);
  const std::size_t J = b.size() - 1;  // segments
  if (count.size() != J || std::accumulate(count.begin(), count.end(), 0) != N_FE_ ||
      *std::min_element(count.begin(), count.end()) < 1)
    return false;
  std::vector<double> t_old(N_FE_ + 1, 0.0);  // old element boundaries
  for (int n = 0; n < N_FE_; ++n) t_old[n + 1] = t_old[n] + w_old[h(n)];
  // The new h of each segment: its length over its count, unless that leaves the bounds of h;
  // then clamp(length / count + nu, lb, ub) with nu such that the interval keeps its length (the
  // switches move; the states of a segment extend its polynomials).
  std::vector<double> h_seg(J);
  auto place = [&](double nu, bool clamp) {
    double total = 0;
    for (std::size_t j = 0; j < J; ++j) {
      const double hj = (t_old[b[j + 1]] - t_old[b[j]]) / count[j] + nu;
      h_seg[j] = clamp ? std::clamp(hj, lb, ub) : hj;
      total += count[j] * h_seg[j];
    }
    return total;
  };
  place(0.0, false);
  if (std::any_of(h_seg.begin(), h_seg.end(),
                  [&](double hj) { return hj < lb - held_tol() || hj > ub + held_tol(); })) {
    const double T = t_old[N_FE_];
    double lo = -T, hi = T;  // place(lo) <= T <= place(hi)
    for (int it = 0; it < 200 && hi - lo > 1e-15 * h0; ++it) {
      const double mid = 0.5 * (lo + hi);
      (place(mid, true) < T ? lo : hi) = mid;
    }
    place(0.5 * (lo + hi), true);
  }
  std::vector<double> t_seg(J + 1, 0.0);  // new segment boundaries
  for (std::size_t j = 0; j < J; ++j) t_seg[j + 1] = t_seg[j] + count[j] * h_seg[j];
  t_seg[J] = t_old[N_FE_];

  // Interpolation nodes of an old element: its start, the stage points strictly inside, its end.
  std::vector<double> tau{0.0};
  std::vector<int> stage_of_node{-1};
  for (int s = 0; s < n_s_; ++s)
    if (tab_.c(s) > 1e-12 && tab_.c(s) < 1.0 - 1e-12) {
      tau.push_back(tab_.c(s));
      stage_of_node.push_back(s);
    }
  tau.push_back(1.0);
  stage_of_node.push_back(n_s_);
  auto state_at = [&](int n, double t, int i) {  // old element n's polynomial at time t
    std::vector<const double*> y;
    for (int s : stage_of_node)
      y.push_back(s < 0 ? &w_old[x(n, 0)] : s == n_s_ ? &w_old[x(n + 1, 0)] : &w_old[X(n, s, 0)]);
    const double hn = w_old[h(n)];
    return lagrange(tau, y, i, hn > 0 ? (t - t_old[n]) / hn : 0.0);
  };
  // The old element of segment j holding t. Elements of length ~0 are skipped: a segment can
  // start with one (a crossing written as {1} -> {0,1} -> {0} through a collapsed element joins
  // the segment after it), and its theta, mixed on the surface, would make the new element's
  // active set {0,1}; fixed, that set holds the element on the surface and collapses it again.
  auto old_element = [&](std::size_t j, double t) {
    int n = b[j];
    while (n + 1 < b[j + 1] && (t_old[n + 1] <= t || collapsed(w_old, n))) ++n;
    return n;
  };

  int e = 0;
  double t = 0;
  for (std::size_t j = 0; j < J; ++j) {
    const double hj = h_seg[j];
    for (int k = 0; k < count[j]; ++k, ++e) {
      const bool last_in_segment = k + 1 == count[j];
      w_new[h(e)] = std::clamp(hj, lb, ub);
      for (int s = 0; s < n_s_; ++s) {
        const double ts = t + tab_.c(s) * hj;
        const int n = old_element(j, ts);
        for (int i = 0; i < n_x; ++i) {
          w_new[X(e, s, i)] = state_at(n, ts, i);
          w_new[V(e, s, i)] = w_old[V(n, s, i)];
        }
        for (int r = 0; r < n_th; ++r) {
          w_new[theta(e, s, r)] = w_old[theta(n, s, r)];
          w_new[lambda(e, s, r)] = w_old[lambda(n, s, r)];
        }
        for (int k2 = 0; k2 < n_sys; ++k2) w_new[mu(e, s, k2)] = w_old[mu(n, s, k2)];
      }
      const double t_end = last_in_segment ? t_seg[j + 1] : t + hj;
      const int n_end = last_in_segment ? b[j + 1] - 1 : old_element(j, t_end);
      if (!stiffly_accurate_) {  // else x_{e+1} is the last stage state, set above
        for (int i = 0; i < n_x; ++i) w_new[x(e + 1, i)] = state_at(n_end, t_end, i);
      }
      if (lambda_end(e, 0) >= 0 && !stiffly_accurate_) {
        for (int r = 0; r < n_th; ++r) w_new[lambda_end(e, r)] = w_old[lambda_end(n_end, r)];
        for (int k2 = 0; k2 < n_sys; ++k2) w_new[mu_end(e, k2)] = w_old[mu_end(n_end, k2)];
      }
      t += hj;
    }
    t = t_seg[j + 1];
  }
  update_lifted_guess(w_new);
  return true;
}

std::vector<FesdInterval::Touch> FesdInterval::touches(const double* w) const {
  std::vector<Touch> out;
  if (!opt_.use_fesd || step_) return out;  // (touches are found in Stewart's form only)
  std::vector<std::vector<int>> active = active_sets(w);
  int prev = -1;  // the last element before n of positive length
  for (int n = 0; n < N_FE_; ++n) {
    if (collapsed(w, n)) continue;  // collapsed: its start point is that of the next element
    const bool switch_here = prev >= 0 && active[n] != active[prev];
    prev = n;
    if (switch_here) continue;                           // a switch, not a touch
    const std::vector<int>& point = points_[n].front();  // lambda at the start of element n
    for (int k = 0; k < model_.n_sys(); ++k) {
      const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
      int n_active = 0, only = -1;
      for (int j = first; j < end; ++j)
        if (has(active[n], j)) ++n_active, only = j;
      if (n_active != 1) continue;
      for (int r = first; r < end; ++r)
        if (r != only && std::abs(w[point[r]]) <= kTouchTol) out.push_back({n, r, only});
    }
  }
  return out;
}

std::vector<std::vector<int>> FesdInterval::probe(const double* w, const Touch& t,
                                                  std::vector<double>& w_new) const {
  std::vector<std::vector<int>> active = active_sets(w);
  std::vector<int>& a = active[t.n];
  std::erase(a, t.instead);
  a.push_back(t.r);
  std::sort(a.begin(), a.end());
  for (int s = 0; s < n_s_; ++s) {
    w_new[theta(t.n, s, t.r)] = w[theta(t.n, s, t.instead)];
    w_new[theta(t.n, s, t.instead)] = 0.0;
  }
  // Collapsed elements right before the touch (length ~0, e.g. both regions active at a free x0
  // on the surface) are part of it: they take the new set too, or they would hold the state on
  // the surface.
  for (int n = t.n - 1; n >= 0 && collapsed(w, n); --n) {
    active[n] = a;
    for (int s = 0; s < n_s_; ++s)
      for (int r = 0; r < model_.n_theta(); ++r) w_new[theta(n, s, r)] = w_new[theta(t.n, s, r)];
  }
  update_lifted_guess(w_new);
  return active;
}

}  // namespace fesd::discretization
