// `quadsketch-cli optimize --symmetry`: a symmetric layout is optimized keeping its mirror pairs
// (report.json's "symmetry" block measures the written state), an asymmetric one is refused
// naming its first node without a mirror, and the flag's value and combinations are checked.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/fixtures.h"

namespace qs {
namespace {

// The bundled example's mesh (a jittered copy under QS_TEST_JITTER, tests/jitter.h).
const std::string kMesh = test::mesh_file(test::assets_dir() + "/example/ellipsoid.obj");
const std::string kSketch = test::assets_dir() + "/example/ellipsoid.layout.json";
const std::string kExact = test::assets_dir() + "/example/ellipsoid_exact.layout.json";

std::string optimize(const std::string& layout, const std::string& out, const std::string& more) {
  return test::cli_path() + " optimize --quiet --mesh " + kMesh + " --layout " + layout +
         " --out " + out + " " + more;
}

TEST(SymmetryCli, ASymmetricLayoutKeepsItsMirrorPairs) {
  const std::string dir = test::temp_dir("cli_symmetry");
  std::string out;
  ASSERT_EQ(test::run_command(optimize(kExact, dir, "--symmetry x"), &out), 0) << out;
  std::ifstream in(dir + "/report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  ASSERT_TRUE(report.contains("symmetry")) << report.dump(2);
  const nlohmann::json& s = report["symmetry"];
  EXPECT_EQ(s["plane"]["axis"], "x");
  EXPECT_NEAR(s["plane"]["normal"][0].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(s["pairs"], 4);  // the cube corners; no node on the plane
  EXPECT_EQ(s["plane_nodes"], 0);
  EXPECT_LT(s["max_pair_error"].get<double>(), 1e-6);
  EXPECT_EQ(report["metrics"]["foldovers"], 0);
  EXPECT_TRUE(report["structurally_equivalent"].get<bool>());
}

TEST(SymmetryCli, AnAsymmetricLayoutIsRefusedNamingTheUnpairedNode) {
  const std::string dir = test::temp_dir("cli_symmetry_refused");
  std::string out;
  const int code = test::run_command(optimize(kSketch, dir, "--symmetry x"), &out);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("not mirror symmetric"), std::string::npos) << out;
  EXPECT_NE(out.find("node 1 (vertex 758) has no mirror node"), std::string::npos) << out;
}

TEST(SymmetryCli, TheAxisAndTheCombinationsAreChecked) {
  const std::string dir = test::temp_dir("cli_symmetry_flags");
  std::string out;
  EXPECT_NE(test::run_command(optimize(kExact, dir, "--symmetry w"), &out), 0);
  EXPECT_NE(out.find("--symmetry"), std::string::npos) << out;
  for (const char* other : {"--no-node-opt", "--discrete-relocation", "--separate-nodes"}) {
    EXPECT_NE(test::run_command(optimize(kExact, dir, std::string("--symmetry y ") + other), &out),
              0)
        << other;
    EXPECT_NE(out.find("--symmetry applies to the continuous node optimization"), std::string::npos)
        << out;
  }
}

}  // namespace
}  // namespace qs
