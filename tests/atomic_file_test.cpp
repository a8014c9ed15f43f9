// write_file_atomic (core/base/atomic_file.h): a target keeps its old content or gets the
// complete new one, and no temporary file is left behind, also when the process is ended by
// another thread in the middle of a write (stop_atomic_writes_for_exit, used by the CLI's
// cancel watchdog).
#include "core/base/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/base/errors.h"
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

// A write the system refuses (in a child process, at a file-size limit: EFBIG, as a full disk
// gives ENOSPC) names the target, not the temporary file, with the system's reason; the target
// keeps its old content and no temporary file is left.
TEST(AtomicFileDeathTest, AWriteErrorNamesTheTargetAndTheSystemsReason) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // the math libraries' threads
  const std::string dir = test::temp_dir("atomic_file_write_error");
  const std::string path = dir + "/out.txt";
  write_file_atomic(path, std::string("old\n"));
  auto child = [&] {
    std::signal(SIGXFSZ, SIG_IGN);  // the write fails with EFBIG instead
    const rlimit limit{4096, 4096};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_file_atomic(path, std::string(1 << 20, 'x'));
    } catch (const QsError& e) {
      std::cerr << e.what() << std::endl;
      std::_Exit(read_file(path) == "old\n" && hidden_files(dir).empty() ? 0 : 2);
    }
    std::_Exit(1);
  };
  // (The threadsafe child runs the test again, in a folder of its own process id.)
  EXPECT_EXIT(child(), testing::ExitedWithCode(0),
              "^cannot write '/[^']*/qs_test_atomic_file_write_error_[0-9]+/out.txt': File too "
              "large\n$");
}

TEST(AtomicFile, WritableFoldersAreCreatedAndCheckedUpFront) {
  const std::string dir = test::temp_dir("atomic_file_writable");
  require_writable_folder(dir + "/new/sub");
  EXPECT_TRUE(fs::is_directory(dir + "/new/sub"));
  EXPECT_TRUE(hidden_files(dir + "/new/sub").empty());  // the probe is gone
  require_writable_file(dir + "/new/out.txt");
  EXPECT_FALSE(fs::exists(dir + "/new/out.txt"));
  const auto refused = [](const std::function<void()>& check, const std::string& message) {
    try {
      check();
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const InvalidInputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
    }
  };
  // A file where a folder is expected.
  std::ofstream(dir + "/plain") << "x\n";
  refused([&] { require_writable_folder(dir + "/plain/sub"); },
          "cannot write into the folder '" + dir + "/plain/sub': ");
  refused([&] { require_writable_folder(dir + "/plain"); },
          "cannot write into the folder '" + dir + "/plain': ");
  refused([&] { require_writable_file(dir + "/plain/out.txt"); },
          "cannot write into the folder '" + dir + "/plain': ");
  // A folder as an output file.
  refused([&] { require_writable_file(dir + "/new"); },
          "cannot write '" + dir + "/new': it is a folder");
  // An existing folder in which no file can be created: without write permission, or for root
  // (whom permissions do not stop) /proc.
  std::string locked = "/proc";
  if (geteuid() != 0) {
    locked = dir + "/locked";
    fs::create_directories(locked);
    fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  }
  refused([&] { require_writable_folder(locked); },
          "cannot write into the folder '" + locked + "': ");
  refused([&] { require_writable_file(locked + "/out.txt"); },
          "cannot write into the folder '" + locked + "': ");
}

}  // namespace
}  // namespace qs
