// core/base/allocator.h: freed solver-sized blocks stay in the process for reuse.
#include "core/base/allocator.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>

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
#endif

// Under glibc's defaults a 20 MB block is a fresh mmap() and goes back to the kernel when
// freed; with the policy it comes from the heap and stays there for the next solve.
TEST(Allocator, KeepsFreedSolverSizedBlocks) {
#if !defined(__GLIBC__) || defined(QS_SANITIZED_MALLOC)
  GTEST_SKIP() << "glibc's malloc only (sanitizers replace it)";
#else
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc."))
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
