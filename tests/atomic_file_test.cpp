// write_file_atomic (core/base/atomic_file.h): a target keeps its old content or gets the
// complete new one, and no temporary file is left behind, also when the process is ended by
// another thread in the middle of a write (stop_atomic_writes_for_exit, used by the CLI's
// cancel watchdog).
#include "core/base/atomic_file.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::vector<std::string> hidden_files(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name[0] == '.') names.push_back(name);
  }
  return names;
}

TEST(AtomicFile, WriterErrorKeepsTheOldContentAndNoTemporaryFile) {
  const std::string dir = test::temp_dir("atomic_file_error");
  const std::string path = dir + "/out.txt";
  write_file_atomic(path, std::string("old\n"));
  EXPECT_THROW(write_file_atomic(path,
                                 [](std::ostream& out) {
                                   out << "half of the new";
                                   throw std::runtime_error("writer failed");
                                 }),
               std::runtime_error);
  EXPECT_EQ(read_file(path), "old\n");
  EXPECT_TRUE(hidden_files(dir).empty());
  write_file_atomic(path, std::string("new\n"));
  EXPECT_EQ(read_file(path), "new\n");
  EXPECT_TRUE(hidden_files(dir).empty());
  EXPECT_THROW(write_file_atomic(dir + "/no/such/folder/out.txt", std::string("x")), QsError);
}

// In a child process (the stop is for good): one thread is inside a write when another stops
// the writes. The temporary file goes at once, the writer never renames it over the target,
// a new write creates nothing, and the target keeps its old content.
TEST(AtomicFileDeathTest, StopForExitRemovesTheWriteInProgressAndBlocksNewOnes) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // the child starts threads
  const std::string dir = test::temp_dir("atomic_file_stop");
  const std::string path = dir + "/out.txt";
  write_file_atomic(path, std::string("old\n"));
  auto child = [&] {
    std::atomic<bool> writing{false}, release{false};
    std::thread writer([&] {
      write_file_atomic(path, [&](std::ostream& out) {
        out << "new, ";
        writing = true;
        while (!release) std::this_thread::sleep_for(1ms);
        out << "complete\n";
      });
    });
    while (!writing) std::this_thread::sleep_for(1ms);
    const bool temp_existed = hidden_files(dir).size() == 1;
    const int removed = stop_atomic_writes_for_exit();
    const bool temp_gone = hidden_files(dir).empty();
    release = true;
    std::thread late([&] { write_file_atomic(dir + "/late.txt", std::string("late\n")); });
    std::this_thread::sleep_for(200ms);
    const bool ok = temp_existed && removed == 1 && temp_gone && hidden_files(dir).empty() &&
                    read_file(path) == "old\n" && !fs::exists(dir + "/late.txt");
    std::_Exit(ok ? 0 : 1);  // the parked writers end with the process
  };
  EXPECT_EXIT(child(), testing::ExitedWithCode(0), "");
  EXPECT_EQ(read_file(path), "old\n");
  EXPECT_TRUE(hidden_files(dir).empty());
}

}  // namespace
}  // namespace qs
