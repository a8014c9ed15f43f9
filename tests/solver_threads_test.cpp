// The math libraries' thread limit (core/base/solver_threads.h): CHOLMOD's OpenMP regions must
// not start their compiled-in 4 threads once the calling thread is limited.
#include "core/base/solver_threads.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "core/base/spd_solver.h"
#include "tests/fixtures.h"

extern "C" double SuiteSparse_time();  // core/base/solver_threads.cpp

namespace qs {
namespace {

int process_threads() {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/task")) ++n;
  return n;
}

// 2D grid Laplacian + identity (SPD), large enough for CHOLMOD's supernodal code to open
// parallel regions.
Eigen::SparseMatrix<double> grid_matrix(int n) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      t.emplace_back(id(i, j), id(i, j), 5.0);
      if (i > 0) t.emplace_back(id(i, j), id(i - 1, j), -1.0);
      if (i + 1 < n) t.emplace_back(id(i, j), id(i + 1, j), -1.0);
      if (j > 0) t.emplace_back(id(i, j), id(i, j - 1), -1.0);
      if (j + 1 < n) t.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  Eigen::SparseMatrix<double> A(n * n, n * n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

TEST(SolverThreads, DefaultAndReset) {
  set_solver_threads(3);
  EXPECT_EQ(solver_threads(), 3);
  set_solver_threads(0);
  EXPECT_EQ(solver_threads(), 1);
}

// With the limit 1, a thread's factorization starts no OpenMP worker and is still right; the
// thread's OpenMP settings say so (when libgomp is loaded).
TEST(SolverThreads, OneThreadFactorizesWithoutHelperThreads) {
  set_solver_threads(1);
  const Eigen::SparseMatrix<double> A = grid_matrix(120);
  const Eigen::VectorXd x_true = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  const Eigen::VectorXd b = A * x_true;
  int before = 0, after = 0, levels = -1;
  double error = 1.0;
  std::thread worker([&] {
    limit_solver_threads_here();
    using GetInt = int (*)();
    if (auto get = reinterpret_cast<GetInt>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels")))
      levels = get();
    before = process_threads();
    SpdSolver solver("threads test");
    for (int k = 0; k < 3; ++k) solver.factorize(A);
    error = (solver.solve(b) - x_true).norm() / x_true.norm();
    after = process_threads();
  });
  worker.join();
  EXPECT_LT(error, 1e-10);
  EXPECT_EQ(after, before) << "the factorization started threads";
  if (levels >= 0) {
    EXPECT_EQ(levels, 0);
  }
  set_solver_threads(0);
}

// The limited thread's parallel regions run inline (solver_threads.cpp defines GOMP_parallel,
// and the executable must export it to CHOLMOD); with two solver threads the regions that ask
// for more threads reach libgomp again. Both factorizations are right.
TEST(SolverThreads, SerialRegionsRunInlineAndOthersReachLibgomp) {
  if (dlsym(RTLD_DEFAULT, "omp_get_max_active_levels") == nullptr)
    GTEST_SKIP() << "CHOLMOD is built without OpenMP here";
  const Eigen::SparseMatrix<double> A = grid_matrix(160);
  const Eigen::VectorXd x_true = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  const Eigen::VectorXd b = A * x_true;
  for (int threads : {1, 2}) {
    set_solver_threads(threads);
    std::uint64_t inline_regions = 0, forwarded = 0;
    double error = 1.0;
    std::thread worker([&] {
      limit_solver_threads_here();
      SpdSolver solver("threads test");
      solver.factorize(A);
      error = (solver.solve(b) - x_true).norm() / x_true.norm();
      inline_regions = inline_parallel_regions_here();
      forwarded = forwarded_parallel_regions_here();
    });
    worker.join();
    EXPECT_LT(error, 1e-10) << threads << " threads";
    EXPECT_GT(inline_regions, 0u) << threads << " threads: CHOLMOD's regions bypass the shim";
    if (threads == 1) {
      EXPECT_EQ(forwarded, 0u) << "a limited thread's region went to libgomp";
    } else {
      EXPECT_GT(forwarded, 0u) << "regions that may use 2 threads must reach libgomp";
    }
  }
  set_solver_threads(0);
}

// CHOLMOD's clock reads (SuiteSparse_time, around every dense BLAS call of its factorization)
// bind to our definition, which reads no clock: the dynamic linker finds it before
// libsuitesparseconfig's, which it shadows.
TEST(SolverThreads, CholmodClockReadsBindToTheSilentDefinition) {
  void* bound = dlsym(RTLD_DEFAULT, "SuiteSparse_time");
  ASSERT_NE(bound, nullptr);
  EXPECT_EQ(bound, reinterpret_cast<void*>(&SuiteSparse_time))
      << "CHOLMOD would call libsuitesparseconfig's clock";
  EXPECT_NE(dlsym(RTLD_NEXT, "SuiteSparse_time"), nullptr) << "nothing to shadow";
  EXPECT_EQ(SuiteSparse_time(), 0.0);
  // The factorization still works without its statistics' clock.
  const Eigen::SparseMatrix<double> A = grid_matrix(60);
  const Eigen::VectorXd x_true = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  const Eigen::VectorXd b = A * x_true;
  SpdSolver solver("clock test");
  solver.factorize(A);
  EXPECT_LT((solver.solve(b) - x_true).norm() / x_true.norm(), 1e-10);
}

// --threads is checked and applied (it used to be accepted and ignored).
TEST(SolverThreads, CommandLineChecksTheCount) {
  if (!std::filesystem::exists(test::cli_path())) GTEST_SKIP() << "quadsketch-cli not built";
  const std::string dir = test::temp_dir("solver_threads_cli");
  const std::string example = test::assets_dir() + "/example/";
  std::string output;
  const std::string base = test::cli_path() + " optimize --quiet --no-node-opt --mesh " + example +
                           "ellipsoid.obj --layout " + example + "ellipsoid.layout.json --out " +
                           dir;
  EXPECT_EQ(test::run_command(base + "/zero --threads 0", &output), 1) << output;  // usage error
  EXPECT_NE(output.find("--threads"), std::string::npos) << output;
  EXPECT_EQ(test::run_command(base + "/one --threads 1", &output), 0) << output;
}

}  // namespace
}  // namespace qs
