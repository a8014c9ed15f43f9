// METIS and signals (core/base/metis_signals.h): a SIGTERM that arrives while another thread
// runs METIS reaches the process's own handler, and the handler is still installed afterwards.
// Without the guard GKlib's handler runs in the signalled thread and longjmp()s into a buffer
// that thread does not have: the test process crashes.
#include "core/base/metis_signals.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>
#include <vector>

#include "core/base/spd_solver.h"

namespace qs {
namespace {

std::atomic<int> g_received{0};

extern "C" void count_signal(int) {
  g_received.fetch_add(1, std::memory_order_relaxed);
}

// The 4-neighbour grid graph of size × size nodes (both directions listed).
void grid_graph(int size, std::vector<int>& start, std::vector<int>& adjacency) {
  const int n = size * size;
  start.assign(n + 1, 0);
  adjacency.clear();
  for (int v = 0; v < n; ++v) {
    const int i = v / size, j = v % size;
    if (i > 0) adjacency.push_back(v - size);
    if (j > 0) adjacency.push_back(v - 1);
    if (j + 1 < size) adjacency.push_back(v + 1);
    if (i + 1 < size) adjacency.push_back(v + size);
    start[v + 1] = static_cast<int>(adjacency.size());
  }
}

TEST(MetisSignals, TheGuardIsBound) {
  EXPECT_TRUE(metis_signal_guard_active())
      << "the executable does not export __sysv_signal (qs_core's link options)";
}

TEST(MetisSignals, SigtermDuringNestedDissectionReachesTheProcessHandler) {
  struct sigaction mine {
  }, before{};
  mine.sa_handler = count_signal;
  sigemptyset(&mine.sa_mask);
  mine.sa_flags = SA_RESTART;
  ASSERT_EQ(sigaction(SIGTERM, &mine, &before), 0);
  g_received = 0;

  std::vector<int> start, adjacency;
  const int size = 300;
  grid_graph(size, start, adjacency);
  std::atomic<bool> done{false};
  std::vector<int> order;
  int orderings = 0;
  std::thread worker([&] {
    // Several orderings, so that signals keep arriving while METIS runs.
    const auto t0 = std::chrono::steady_clock::now();
    do {
      order = nested_dissection_ordering(size * size, start, adjacency);
      ++orderings;
    } while (!order.empty() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(1));
    done = true;
  });
  int sent = 0;
  while (!done) {
    kill(getpid(), SIGTERM);  // process-directed, as `kill PID` sends it
    ++sent;
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  worker.join();

  struct sigaction after {};
  ASSERT_EQ(sigaction(SIGTERM, nullptr, &after), 0);
  const bool still_mine = after.sa_handler == count_signal;
  ASSERT_EQ(sigaction(SIGTERM, &before, nullptr), 0);  // the test runner's again

  EXPECT_TRUE(still_mine) << "METIS left another SIGTERM handler installed";
  EXPECT_GT(g_received.load(), 0) << sent << " signals sent, none reached the handler";
  ASSERT_EQ(order.size(), static_cast<size_t>(size * size)) << "the ordering failed";
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < size * size; ++k) ASSERT_EQ(sorted[k], k) << "not a permutation";
  std::cerr << orderings << " orderings, " << sent << " signals sent, " << g_received.load()
            << " received\n";
}

}  // namespace
}  // namespace qs
