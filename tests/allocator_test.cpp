// core/base/allocator.h: freed solver-sized blocks stay in the process for reuse.
#include "core/base/allocator.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define QS_SANITIZED_MALLOC 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define QS_SANITIZED_MALLOC 1
#endif
#endif

namespace qs {
namespace {

#if defined(__GLIBC__) && !defined(QS_SANITIZED_MALLOC)
// A 20 MB block, written so that the allocation is not optimized away.
void* touched_block(size_t bytes) {
  void* p = std::malloc(bytes);
  if (p) std::memset(p, 1, bytes);
  volatile unsigned char* v = static_cast<unsigned char*>(p);
  if (v) v[bytes - 1] = 2;
  return p;
}

// Does the environment set glibc malloc tunables (then the policy is not applied)?
bool user_sets_malloc_tunables() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return tunables && std::strstr(tunables, "glibc.malloc.");
}
#endif

// Under glibc's defaults a 20 MB block is a fresh mmap() and goes back to the kernel when
// freed; with the policy it comes from the heap and stays there for the next solve.
TEST(Allocator, KeepsFreedSolverSizedBlocks) {
#if !defined(__GLIBC__) || defined(QS_SANITIZED_MALLOC)
  GTEST_SKIP() << "glibc's malloc only (sanitizers replace it)";
#else
  if (user_sets_malloc_tunables())
    GTEST_SKIP() << "GLIBC_TUNABLES sets malloc tunables: the policy leaves them alone";
  ASSERT_TRUE(keep_freed_memory());
  constexpr size_t kBytes = 20u << 20;
  const size_t mapped_before = mallinfo2().hblkhd;
  void* block = touched_block(kBytes);
  ASSERT_NE(block, nullptr);
  EXPECT_LT(mallinfo2().hblkhd, mapped_before + kBytes) << "the block was mmap()ed";
  std::free(block);
  EXPECT_GE(mallinfo2().fordblks, kBytes) << "the freed block went back to the kernel";
#endif
}

#if defined(__GLIBC__) && !defined(QS_SANITIZED_MALLOC)
// The arenas malloc_info() lists (one <heap nr="…"> element each).
int malloc_arenas() {
  char* text = nullptr;
  size_t size = 0;
  FILE* f = open_memstream(&text, &size);
  if (!f) return -1;
  malloc_info(0, f);
  std::fclose(f);
  int n = 0;
  for (const char* p = text; (p = std::strstr(p, "<heap nr=")) != nullptr; ++p) ++n;
  std::free(text);
  return n;
}
#endif

// Threads that allocate while all of them are alive share at most kept_memory_arena_limit()
// arenas (glibc alone would give each of them its own, up to 8 per core), so the memory each
// arena keeps for reuse is not multiplied by the solver threads.
TEST(Allocator, ThreadsShareTheLimitedArenas) {
#if !defined(__GLIBC__) || defined(QS_SANITIZED_MALLOC)
  GTEST_SKIP() << "glibc's malloc only (sanitizers replace it)";
#else
  if (user_sets_malloc_tunables())
    GTEST_SKIP() << "GLIBC_TUNABLES sets malloc tunables: the policy leaves them alone";
  ASSERT_TRUE(keep_freed_memory());
  const int limit = kept_memory_arena_limit();
  ASSERT_GE(limit, 2);
  const int threads = limit + 4;
  std::mutex m;
  std::condition_variable cv;
  int allocated = 0;
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      void* p = touched_block(1 << 16);
      std::unique_lock<std::mutex> lock(m);
      ++allocated;
      cv.notify_all();
      cv.wait(lock, [&] { return allocated == threads; });  // all alive, each with its block
      lock.unlock();
      std::free(p);
    });
  for (auto& t : pool) t.join();
  const int arenas = malloc_arenas();
  EXPECT_GE(arenas, 1);
  EXPECT_LE(arenas, limit) << threads << " threads";
#endif
}

// The top pad counts against an address-space or data limit: under one it is at most 1/64 of
// the limit (checked in a child process, which lowers its own data limit to 640 MB).
TEST(Allocator, TopPadShrinksUnderAMemoryLimit) {
  constexpr std::size_t kFull = std::size_t(256) << 20;
  const auto limit_of = [](int resource) {
    struct rlimit l {};
    return getrlimit(resource, &l) == 0 ? l.rlim_cur : RLIM_INFINITY;
  };
  std::size_t expected = kFull;
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA})
    if (limit_of(resource) != RLIM_INFINITY)
      expected = std::min<std::size_t>(expected, limit_of(resource) / 64);
  EXPECT_EQ(kept_memory_top_pad(), expected);
  constexpr rlim_t kData = rlim_t(640) << 20;
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    struct rlimit l {};
    if (getrlimit(RLIMIT_DATA, &l) != 0) _exit(2);
    if (l.rlim_cur == RLIM_INFINITY || l.rlim_cur > kData) l.rlim_cur = kData;
    if (setrlimit(RLIMIT_DATA, &l) != 0) _exit(3);
    _exit(kept_memory_top_pad() <= std::size_t(kData / 64) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the pad ignores the limit; 2, 3: getrlimit/setrlimit";
}

TEST(Allocator, LeavesMallocTunablesOfTheUserAlone) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "glibc only";
#else
  const char* old = std::getenv("GLIBC_TUNABLES");
  const std::string saved = old ? old : "";
  setenv("GLIBC_TUNABLES", "glibc.malloc.trim_threshold=4096", 1);
  EXPECT_FALSE(keep_freed_memory());
  if (old)
    setenv("GLIBC_TUNABLES", saved.c_str(), 1);
  else
    unsetenv("GLIBC_TUNABLES");
#endif
}

}  // namespace
}  // namespace qs
