// quadsketch-cli's checks of its options, outputs and resources (issue #44): every numeric
// option is validated at parse time, outputs are checked before any computation, a write error
// names the file and the system's reason, and memory exhaustion is a clean exit with a message.
// (import-quads' checks of its own output: quad_import_test.cpp.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;

const std::string kMesh = test::assets_dir() + "/example/ellipsoid.obj";
const std::string kLayout = test::assets_dir() + "/example/ellipsoid.layout.json";

std::string cli(const std::string& args) {
  return test::cli_path() + " " + args;
}

// The exit code of \p args run by bash after \p limits (e.g. "ulimit -v 100000"), at most
// 120 s (a hang fails instead of blocking the suite). 128 + N: killed by signal N.
int run_limited(const std::string& limits, const std::string& args, std::string* out,
                const std::string& env = "") {
  return test::run_command(env + " timeout 120 bash -c '" + limits + "; exec " + cli(args) + "'",
                           out);
}

int count_lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// ---- numeric options ----

struct BadValues {
  std::string command;  // subcommand with every required option except the tested one
  std::string flag;
  std::vector<std::string> values;
};

// Every numeric option of every subcommand, with values that must fail at parse time:
// 0/negative where invalid, NaN, infinities and absurd magnitudes. Nothing runs: no output
// folder appears.
TEST(CliChecks, EveryNumericOptionRejectsBadValuesAtParseTime) {
  const std::string dir = test::temp_dir("cli_checks_options");
  const std::string out = dir + "/out";
  const std::string quads = dir + "/cube.obj";
  test::write_obj(test::quad_cube(2), quads);
  const std::string files = " --mesh " + kMesh + " --layout " + kLayout;
  const std::string field = "field" + files + " --out " + out;
  const std::string optimize = "optimize" + files + " --out " + out;
  const std::string import = "import-quads --quads " + quads + " --out " + out;
  const std::string perturb = "perturb" + files + " --out " + out + "/p.json";
  const std::string cage = "cage-layout --mesh " + kMesh + " --out " + out + "/c.json";
  // Invalid for every option; 1e300 too except as --quad-size (one quad per patch side).
  const std::vector<std::string> common = {"nan", "NaN", "inf", "-inf", "-1e300"};
  const std::vector<BadValues> table = {
      {field, "--sharp-angle", {"-1", "181", "-1000", "1e300"}},
      {field, "--max-cluster-faces", {"-1", "1e10", "1e300"}},
      {optimize, "--steps", {"-5", "-1", "1000000", "1e300"}},
      {optimize, "--quad-size", {"0", "-1", "-1e-3"}},
      {optimize, "--quad-count", {"0", "-1", "10000001", "1e10", "1e300"}},
      {optimize, "--time-limit", {"0", "-2", "1e9", "1e300"}},
      {optimize, "--sharp-angle", {"-1000", "181", "1e300"}},
      {optimize, "--max-cluster-faces", {"-1", "1e300"}},
      {optimize, "--threads", {"0", "-1", "65", "1000", "1e300"}},
      {import, "--refine", {"0", "-1", "1001", "1e300"}},
      {import, "--coarsen", {"-1", "1e7", "1e300"}},
      {perturb + " --seed 1", "--rings", {"0", "-1", "1001", "1e300"}},
      {perturb + " --rings 1", "--seed", {"-1", "4294967296", "1e300"}},
      {cage, "--resolution", {"0", "1", "201", "1e300"}},
      {cage, "--smoothing", {"-1", "100000", "1e300"}},
      {cage, "--attempts", {"0", "-1", "401", "1e300"}},
      {cage, "--coarsen", {"-1", "1001", "1e300"}},
      {cage, "--subsamples", {"0", "9", "1e300"}},
  };
  int checked = 0;
  for (const BadValues& row : table) {
    std::vector<std::string> values = row.values;
    values.insert(values.end(), common.begin(), common.end());
    for (const std::string& value : values) {
      std::string output;
      const int code = test::run_command(cli(row.command + " " + row.flag + " " + value), &output);
      const std::string what = row.flag + " " + value + ":\n" + output;
      EXPECT_EQ(code, 1) << what;
      EXPECT_NE(output.find(row.flag), std::string::npos) << what;
      EXPECT_NE(output.find(value), std::string::npos) << what;
      EXPECT_FALSE(fs::exists(out)) << what << "(an output folder was made)";
      ++checked;
    }
  }
  EXPECT_GE(checked, 150);
}

// A quad size that would make more quads than the limit is refused after the mesh is loaded,
// before the optimization, with the estimate (the example's surface area is 12.8) and the
// smallest acceptable size. (1e-3 wrote a 2.1 GB quads.obj of 12.4 million quads.)
TEST(CliChecks, QuadMeshesOverTheLimitAreRefusedBeforeTheComputation) {
  const std::string dir = test::temp_dir("cli_checks_quads");
  const std::vector<std::array<std::string, 3>> cases = {{"1e-3", "0.001", "1.28e+07"},
                                                         {"1e-4", "0.0001", "1.28e+09"}};
  for (const auto& [size, printed, count] : cases) {
    std::string output;
    EXPECT_EQ(test::run_command(cli("optimize --mesh " + kMesh + " --layout " + kLayout +
                                    " --quad-size " + size + " --out " + dir),
                                &output),
              2)
        << output;
    EXPECT_EQ(count_lines(output), 1) << output;  // no progress: nothing was computed
    EXPECT_NE(output.find("error: --quad-size " + printed + " would make " + count +
                          " quads (estimated: surface area 12.8 / quad "
                          "size²), more than the limit of 10000000; use a --quad-size of at "
                          "least 0.00113"),
              std::string::npos)
        << output;
    EXPECT_FALSE(fs::exists(dir + "/quads.obj"));
    EXPECT_FALSE(fs::exists(dir + "/param.obj"));
  }
}

// ---- outputs ----

// Every subcommand that writes checks its output folder before it computes anything: a file
// where a folder is expected, and an existing folder where no file can be created (a folder
// without write permission; as root, whom permissions do not stop, /proc).
TEST(CliChecks, UnwritableOutputsAreRefusedBeforeAnyComputation) {
  const std::string dir = test::temp_dir("cli_checks_unwritable");
  const std::string quads = dir + "/cube.obj";
  test::write_obj(test::quad_cube(2), quads);
  std::ofstream(dir + "/plain") << "a file\n";
  std::string locked = "/proc";
  if (geteuid() != 0) {
    locked = dir + "/locked";
    fs::create_directories(locked);
    fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const std::string files = " --mesh " + kMesh + " --layout " + kLayout;
  for (const std::string& folder : {dir + "/plain/sub", locked}) {
    const std::map<std::string, std::string> commands = {
        {"validate", "validate" + files + " --out " + folder},
        {"field", "field" + files + " --out " + folder},
        {"optimize", "optimize" + files + " --out " + folder},
        {"import-quads", "import-quads --quads " + quads + " --out " + folder},
        {"perturb", "perturb" + files + " --rings 1 --seed 1 --out " + folder + "/p.json"},
        {"cage-layout", "cage-layout --mesh " + kMesh + " --out " + folder + "/c.json"},
        {"cage-layout --cage",
         "cage-layout --mesh " + kMesh + " --out " + dir + "/c.json --cage " + folder + "/c.obj"},
    };
    for (const auto& [name, args] : commands) {
      std::string output;
      EXPECT_EQ(test::run_command(cli(args), &output), 2) << name << ": " << output;
      // One line, the error: no warning, progress or result of a computation before it.
      EXPECT_EQ(output.rfind("error: cannot write into the folder '" + folder + "': ", 0), 0u)
          << name << ": " << output;
      EXPECT_EQ(count_lines(output), 1) << name << ": " << output;
    }
  }
  EXPECT_FALSE(fs::exists(dir + "/c.json"));
  std::string output;
  EXPECT_EQ(test::run_command(cli("perturb --mesh " + kMesh + " --layout " + kLayout +
                                  " --rings 1 --seed 1 --out " + dir),
                              &output),
            2)
      << output;
  EXPECT_NE(output.find("cannot write '" + dir + "': it is a folder"), std::string::npos) << output;
}

// A write that fails (here at a file-size limit, EFBIG; a full disk gives ENOSPC the same way)
// names the file it was writing, never its temporary file, with the system's reason, and
// leaves no temporary file behind.
TEST(CliChecks, WriteErrorsNameTheFileAndTheReason) {
  const std::string dir = test::temp_dir("cli_checks_write_error");
  test::write_obj(test::quad_cube(4), dir + "/cube.obj");
  const std::string out = dir + "/out";
  std::string output;
  // 8 KB: report.json fits, the refined mesh.obj (6000 vertices) does not.
  EXPECT_EQ(
      run_limited("ulimit -f 8",
                  "import-quads --quads " + dir + "/cube.obj --refine 8 --out " + out, &output),
      1)
      << output;
  EXPECT_NE(output.find("error: cannot write '" + out + "/mesh.obj': File too large"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find(".tmp"), std::string::npos) << output;
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
  EXPECT_FALSE(fs::exists(out + "/mesh.obj"));
}

// ---- memory ----

// validate on a layout of 300,000 nodes on shared vertices: the issues of one kind are listed
// up to a limit and summarized, so the report fits where listing all of them would not; with
// too little memory even to read the layout, the run ends with "out of memory while loading the
// layout" and exit code 1, never a signal. The limits are measured from the smallest address
// space in which validate runs the bundled example; the allocator's padding (keep_freed_memory)
// and OpenBLAS's per-core threads are turned off so that this does not depend on the machine.
TEST(CliChecks, OutOfMemoryIsACleanExitAndRepeatedIssuesAreSummarized) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan reserves terabytes of address space (no run fits under ulimit -v) and "
                  "replaces the allocator that throws std::bad_alloc";
#endif
  const std::string dir = test::temp_dir("cli_checks_memory");
  const std::string layout = dir + "/shared.layout.json";
  {
    std::ofstream out(layout);
    out << "{\"format\": \"quadsketch-layout\", \"version\": 1, \"nodes\": [";
    for (int i = 0; i < 300000; ++i)
      out << (i ? ", " : "") << "{\"id\": " << i << ", \"vertex\": " << i % 866 << "}";
    out << "], \"arcs\": []}\n";
  }
  const std::string env = "OPENBLAS_NUM_THREADS=1 GLIBC_TUNABLES=glibc.malloc.top_pad=0";
  const auto runs_in = [&](long kb) {
    return run_limited("ulimit -v " + std::to_string(kb),
                       "validate --mesh " + kMesh + " --layout " + kLayout, nullptr, env) == 0;
  };
  long lo = 16 * 1024, hi = 16 * 1024 * 1024;  // KB
  ASSERT_TRUE(runs_in(hi));
  while (hi - lo > 4096) {
    const long mid = (lo + hi) / 2;
    (runs_in(mid) ? hi : lo) = mid;
  }
  // The allocator's policy (its padding on) needs no more room under the limit: its top pad
  // shrinks to a 64th of the limit (a pad of 256 MB needed that much more).
  EXPECT_EQ(run_limited("ulimit -v " + std::to_string(hi + 64 * 1024),
                        "validate --mesh " + kMesh + " --layout " + kLayout, nullptr,
                        "OPENBLAS_NUM_THREADS=1"),
            0)
      << "limit " << hi + 64 * 1024 << " KB";
  std::string output;
  const std::string validate = "validate --mesh " + kMesh + " --layout " + layout;
  // Reading the layout needs about 190 MB more than the example.
  EXPECT_EQ(run_limited("ulimit -v " + std::to_string(hi + 32 * 1024), validate, &output, env), 1)
      << output;
  EXPECT_NE(output.find("error: out of memory while loading the layout '" + layout + "'"),
            std::string::npos)
      << output;
  // Listing every issue would take 2.6 KB each (780 MB).
  EXPECT_EQ(run_limited("ulimit -v " + std::to_string(hi + 450 * 1024), validate, &output, env), 2)
      << output;
  EXPECT_NE(output.find("error [nodes_share_vertex] … and 299114 more of the same kind"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("invalid layout: 299134 error(s)"), std::string::npos) << output;
  EXPECT_LT(count_lines(output), 100) << output;
}

}  // namespace
}  // namespace qs
