// fesd::Stepper allocates nothing in its steps on the active-set path once the active-set shapes
// have been met (include/fesd/stepper.hpp, docs/active-set.md "Stepping API").
//
// Its own executable (fesd_stepper_allocation_test): it replaces the global operator new / delete
// and glibc's malloc family (forwarding to __libc_malloc etc.), so that it counts the allocations
// of C++ containers, of Eigen (which calls malloc directly) and of KLU (SuiteSparse's malloc) made
// anywhere in the process, libfesd included. Counting is on only between start() and stop().
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "../../bench/oscillator_model.hpp"
#include "fesd/integrator.hpp"
#include "fesd/stepper.hpp"
#include "integrator/stepper_models.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> counting{false};
std::atomic<long> news{0}, mallocs{0};

void start() {
  news = 0;
  mallocs = 0;
  counting = true;
}
void stop() {
  counting = false;
}
}  // namespace

// ---- the malloc family (glibc supports replacing it; these forward to its own allocator) ----
extern "C" {
void* malloc(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++mallocs;
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) ++mallocs;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++mallocs;
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++mallocs;
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  return memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  *out = memalign(alignment, n);
  return *out == nullptr ? ENOMEM : 0;
}
void free(void* p) {
  __libc_free(p);
}
}

// ---- operator new / delete ----
void* operator new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++news;
  if (void* p = __libc_malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  return operator new(n);
}
void* operator new(std::size_t n, std::align_val_t a) {
  if (counting.load(std::memory_order_relaxed)) ++news;
  if (void* p = __libc_memalign(static_cast<std::size_t>(a), n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return operator new(n, a);
}
void operator delete(void* p) noexcept {
  __libc_free(p);
}
void operator delete[](void* p) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}

namespace {

const Eigen::VectorXd none;  // u, p: zero controls, the model's p_default

/// N steps from x0, twice: the first pass meets the shapes (and is compared with integrate()),
/// reset(), then the second pass is counted. Both passes give the states of integrate() to 1e-12.
void expect_no_allocation(const fesd::Pss& model, const Eigen::VectorXd& x0, double h, int N,
                          const fesd::IntegratorOptions& o) {
  const fesd::IntegratorResult r = fesd::integrate(model, x0, N * h, N, o);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.summary.homotopy_path_steps, 0);  // every step on the active-set path
  fesd::Stepper stepper(model, h, o);
  Eigen::VectorXd x = x0;
  for (int pass = 0; pass < 2; ++pass) {
    x = x0;
    stepper.reset();
    int failed = 0;
    if (pass == 1) start();
    for (int k = 0; k < N; ++k) failed += stepper.step(x, none, none, x) != fesd::Status::Success;
    stop();
    ASSERT_EQ(failed, 0);
    EXPECT_LE((x - r.x_final()).lpNorm<Eigen::Infinity>(), 1e-12) << "pass " << pass;
  }
  EXPECT_EQ(news.load(), 0) << "operator new calls in " << N << " steps";
  EXPECT_EQ(mallocs.load(), 0) << "malloc calls in " << N << " steps";
  EXPECT_EQ(stepper.stats().homotopy_steps, 0);
}

// The counters themselves work: a std::vector (operator new), an Eigen vector (malloc), and
// integrate() (allocates plenty, in libfesd).
std::vector<double>* volatile keep_vector = nullptr;
TEST(StepperAllocation, CountersCount) {
  start();
  keep_vector = new std::vector<double>(100);
  Eigen::VectorXd e(100);
  e.setZero();
  stop();
  EXPECT_EQ(news.load(), 2);
  EXPECT_GE(mallocs.load(), 1);
  delete keep_vector;
  start();
  const fesd::IntegratorResult r =
      fesd::integrate(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), 0.1, 2);
  stop();
  EXPECT_GT(news.load(), 100);
  EXPECT_GT(mallocs.load(), 10);
}

// The oscillator (47), one crossing at t = 1 (in a step's interior), 200 steps over [0, 2].
TEST(StepperAllocation, OscillatorNoAllocation) {
  fesd::IntegratorOptions o;
  o.discretization.n_s = 3;
  expect_no_allocation(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), 0.01, 200, o);
}

// Entering a sliding mode, sliding, leaving it (stepper_models.hpp), 300 steps over [0, 3].
TEST(StepperAllocation, SlidingNoAllocation) {
  expect_no_allocation(fesd_test::sliding_exit_model(), fesd_test::sliding_exit_x0(), 0.01, 300,
                       {});
}

}  // namespace
