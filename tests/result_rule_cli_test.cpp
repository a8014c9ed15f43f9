// The rule for optimize's result (docs/interfaces.md, report.json): the lowest E among the
// fold-free, structurally equivalent states the optimization reached, never worse than a
// fold-free input. The case (assets/repro/cube_thin1e-3.obj, a cube-sphere quad layout with a
// strip of relative width 1e-3) is fold-free at the start; its later states fold, or trace
// badly through the thin strip.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/fixtures.h"

namespace qs {
namespace {

TEST(ResultRule, NeverWorseThanAFoldFreeStateTheOptimizationReached) {
  const std::string dir = test::temp_dir("result_rule");
  const std::string quads = test::mesh_file(test::assets_dir() + "/repro/cube_thin1e-3.obj");
  std::string log;
  ASSERT_EQ(test::run_command(test::cli_path() + " import-quads --all-edges --refine 3 --quads " +
                                  quads + " --out " + dir + "/in",
                              &log),
            0)
      << log;
  ASSERT_EQ(test::run_command(test::cli_path() + " optimize --steps 10 --mesh " + dir +
                                  "/in/mesh.obj --layout " + dir + "/in/layout.json --out " + dir +
                                  "/out",
                              &log),
            0)
      << log;
  // The input as it is (no node movement): fold-free, and structurally equivalent or not.
  ASSERT_EQ(test::run_command(test::cli_path() + " optimize --no-node-opt --mesh " + dir +
                                  "/in/mesh.obj --layout " + dir + "/in/layout.json --out " + dir +
                                  "/input",
                              &log),
            0)
      << log;
  const auto read = [&](const std::string& sub) {
    std::ifstream in(dir + "/" + sub + "/report.json");
    return nlohmann::json::parse(in);
  };
  const auto input = read("input");
  const auto report = read("out");
  const bool input_equivalent = input["structurally_equivalent"].get<bool>();
  const bool equivalent = report["structurally_equivalent"].get<bool>();
  const double E_init = input["E_final"].get<double>();
  std::printf("[stat] thin strip: input E %.6g (equivalent %d), result E %.6g (equivalent %d)\n",
              E_init, int(input_equivalent), report["E_final"].get<double>(), int(equivalent));
  ASSERT_EQ(input["metrics"]["foldovers"].get<int>(), 0) << "the case's premise: a fold-free input";
  EXPECT_EQ(report["metrics"]["foldovers"].get<int>(), 0);
  if (input_equivalent) {
    EXPECT_TRUE(equivalent);
  }
  if (equivalent == input_equivalent) {
    EXPECT_LE(report["E_final"].get<double>(), E_init * (1 + 1e-6));
  }
  // The last accepted step reported is the state written.
  double last_accepted = report["E_init"].get<double>();
  for (const auto& step : report["steps"])
    if (step["accepted"].get<bool>()) last_accepted = step["E"].get<double>();
  EXPECT_NEAR(report["E_final"].get<double>(), last_accepted, 1e-9 * E_init);
}

}  // namespace
}  // namespace qs
