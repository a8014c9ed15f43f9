// quadsketch-cli under SIGTERM/SIGINT (issue #10): an interrupted `optimize --no-node-opt`
// leaves only complete files in its output folder (each output old or new, never torn, no
// temporary leftovers), report.json says "cancelled" (exit 143 / 130) or "ok" (exit 0, when
// the run finished first), and the process never hangs.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/layout/layout_io.h"
#include "tests/fixtures.h"

extern char** environ;

namespace qs {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

struct BigInput {
  std::string dir, mesh, layout;
  int faces = 0;
};

// cube_sphere(k) has 12 k² triangles: k = 60 gives 43 200 (`--no-node-opt`: about 0.3 s).
const BigInput& big_input() {
  static const BigInput input = [] {
    BigInput in;
    in.dir = test::temp_dir("signals_input");
    const test::MeshAndLayout ml = test::cube_sphere(60, Vec3(1.3, 1, 0.75));
    in.mesh = in.dir + "/big.obj";
    in.layout = in.dir + "/big.layout.json";
    test::write_obj(ml.mesh, in.mesh);
    save_layout(ml.layout, in.layout, &ml.mesh);
    in.faces = static_cast<int>(ml.mesh.n_faces());
    return in;
  }();
  return input;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

//! Starts the CLI (stdout+stderr to \p log) and returns its pid.
pid_t spawn_cli(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> argv_s = {test::cli_path()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

//! Whether process \p pid has installed a handler for \p signo (Linux: the SigCgt mask of
//! /proc/<pid>/status). Before that, the signal takes its default action: the process dies
//! without touching its output folder, which is the kernel's doing, not the CLI's.
bool catches_signal(pid_t pid, int signo) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("SigCgt:")) continue;
    const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
    return ((mask >> (signo - 1)) & 1ULL) != 0;
  }
  return false;
}

//! Waits for \p pid up to \p timeout; returns the exit code, 128 + signal when it was killed
//! by a signal, or -1 on a timeout (the process is then killed).
int wait_exit(pid_t pid, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) {
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
      return -2;
    }
    std::this_thread::sleep_for(10ms);
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

//! Every file in \p dir is complete: no temporary leftovers, JSON parses, param.obj has all its
//! faces, field.txt one line per face. Returns report.json's status ("" when absent).
std::string check_folder(const std::string& dir, int faces) {
  std::string status;
  if (!fs::exists(dir)) return status;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    EXPECT_NE(name[0], '.') << "leftover temporary file " << name;
    const std::string text = read_text(entry.path());
    if (name.ends_with(".json")) {
      nlohmann::json j;
      EXPECT_NO_THROW(j = nlohmann::json::parse(text)) << "torn JSON file " << name;
      if (name == "report.json" && j.is_object()) status = j.value("status", "");
      if (name == "layout.json") {
        EXPECT_NO_THROW((void)parse_layout_json(text, name));
      }
    } else if (name == "param.obj") {
      int f_lines = 0;
      std::istringstream in(text);
      for (std::string line; std::getline(in, line);) f_lines += line.starts_with("f ");
      EXPECT_EQ(f_lines, faces) << "torn param.obj";
      EXPECT_TRUE(text.ends_with("\n"));
    } else if (name == "field.txt") {
      int lines = 0;
      for (char c : text) lines += (c == '\n');
      EXPECT_EQ(lines, faces) << "torn field.txt";
    }
  }
  return status;
}

struct RunOutcome {
  int exit_code = 0;
  std::string status;
  double seconds = 0;
};

// \p node_opt: the whole pipeline (5 node optimization steps, seconds) instead of
// --no-node-opt (about 0.3 s on an idle machine).
RunOutcome run_and_signal(const std::string& out, int signo, std::chrono::milliseconds delay,
                          bool node_opt = false) {
  const BigInput& in = big_input();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> args = {"optimize", "--quiet", "--mesh", in.mesh,
                                   "--layout", in.layout, "--out",  out};
  if (node_opt) {
    args.insert(args.end(), {"--steps", "5"});
  } else {
    args.push_back("--no-node-opt");
  }
  const pid_t pid = spawn_cli(args, out + ".log");
  EXPECT_GT(pid, 0);
  RunOutcome r;
  if (pid <= 0) return r;
  // Count the delay from the moment the run has started working, not from the spawn: on a
  // loaded machine start-up alone (loading the shared libraries) can take a second. The run
  // catches the signal first thing in main(), then creates its output folder (a rerun finds
  // it there already).
  for (int i = 0; i < 6000 && !catches_signal(pid, signo); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_TRUE(catches_signal(pid, signo)) << "the CLI never installed its signal handler";
  for (int i = 0; i < 6000 && !std::filesystem::exists(out); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(delay);
  kill(pid, signo);
  r.exit_code = wait_exit(pid, 120s);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(r.exit_code, -1) << "the CLI did not stop within 120 s after the signal (hang)";
  r.status = check_folder(out, in.faces);
  return r;
}

void expect_cancelled_or_ok(const RunOutcome& r, int signo, const std::string& log) {
  SCOPED_TRACE(read_text(log));
  if (r.status == "ok") {
    EXPECT_EQ(r.exit_code, 0);
  } else {
    EXPECT_EQ(r.status, "cancelled");
    EXPECT_EQ(r.exit_code, 128 + signo);
  }
}

TEST(Signals, SigtermAtVariousMomentsLeavesOnlyCompleteFiles) {
  const std::string base = test::temp_dir("signals_term");
  int cancelled = 0;
  // --no-node-opt runs (about as long as the first delays: start, solve or writing) and whole
  // pipelines (signalled during the node optimization).
  const std::pair<int, bool> moments[] = {{100, false}, {250, false}, {1000, true}, {2500, true}};
  for (const auto& [delay_ms, node_opt] : moments) {
    SCOPED_TRACE("delay " + std::to_string(delay_ms) + " ms" + (node_opt ? ", node opt" : ""));
    const std::string out = base + "/run" + std::to_string(delay_ms);
    const RunOutcome r =
        run_and_signal(out, SIGTERM, std::chrono::milliseconds(delay_ms), node_opt);
    expect_cancelled_or_ok(r, SIGTERM, out + ".log");
    cancelled += (r.status == "cancelled");
    std::cerr << "SIGTERM after " << delay_ms << " ms: exit " << r.exit_code << ", status "
              << r.status << ", " << r.seconds << " s\n";
  }
  EXPECT_GT(cancelled, 0) << "every run finished before the signal: use a bigger mesh";
}

TEST(Signals, SigintGivesExitCode130) {
  const std::string out = test::temp_dir("signals_int") + "/out";
  // The whole pipeline: --no-node-opt on this input can end before the signal.
  const RunOutcome r = run_and_signal(out, SIGINT, 300ms, true);
  expect_cancelled_or_ok(r, SIGINT, out + ".log");
  EXPECT_EQ(r.status, "cancelled");
}

TEST(Signals, InterruptedRerunKeepsTheOldCompleteOutputs) {
  // A first, complete run; then a rerun into the same folder, interrupted at various moments:
  // every output is still complete (the old version or the new one).
  const BigInput& in = big_input();
  const std::string out = test::temp_dir("signals_rerun") + "/out";
  std::string log;
  ASSERT_EQ(test::run_command(test::cli_path() + " optimize --no-node-opt --quiet --mesh " +
                                  in.mesh + " --layout " + in.layout + " --out " + out,
                              &log),
            0)
      << log;
  ASSERT_EQ(check_folder(out, in.faces), "ok");
  // The temporary file of a run killed outright: the rerun removes it.
  write_file_atomic((fs::path(out) / ".param.obj.tmpAbC123").string(), std::string("v 0 0 0\n"));
  for (int delay_ms : {300, 1500}) {
    SCOPED_TRACE("delay " + std::to_string(delay_ms) + " ms");
    const RunOutcome r = run_and_signal(out, SIGTERM, std::chrono::milliseconds(delay_ms));
    expect_cancelled_or_ok(r, SIGTERM, out + ".log");
    for (const char* name : {"param.obj", "field.txt", "layout.json"})
      EXPECT_TRUE(fs::exists(fs::path(out) / name)) << name << " lost";
  }
}

}  // namespace
}  // namespace qs
