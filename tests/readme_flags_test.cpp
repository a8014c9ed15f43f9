// The README's command synopsis is complete: every long option that `quadsketch-cli` and each
// of its subcommands print in `--help` appears in README.md.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "tests/fixtures.h"

namespace qs {
namespace {

std::set<std::string> long_options(const std::string& help) {
  std::set<std::string> out;
  static const std::regex option(R"((^|[\s,])(--[a-z][a-z0-9-]*))");
  std::istringstream lines(help);
  std::string line;
  bool in_options = false;
  while (std::getline(lines, line)) {
    if (line.rfind("Options:", 0) == 0) in_options = true;
    if (line.rfind("Subcommands:", 0) == 0) in_options = false;
    if (!in_options) continue;
    // Only the option column (the description may mention other commands' options).
    const std::string head = line.substr(0, std::min<size_t>(line.size(), 30));
    for (std::sregex_iterator it(head.begin(), head.end(), option), end; it != end; ++it)
      out.insert((*it)[2].str());
  }
  return out;
}

TEST(Readme, EveryCommandLineOptionIsDocumented) {
  std::ifstream in(test::assets_dir() + "/../README.md");
  ASSERT_TRUE(in) << "README.md not found next to assets/";
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string readme = buffer.str();
  int checked = 0;
  for (const std::string sub :
       {"", "validate", "field", "optimize", "import-quads", "perturb", "cage-layout"}) {
    std::string help;
    ASSERT_EQ(test::run_command(test::cli_path() + " " + sub + " --help", &help), 0) << help;
    const auto options = long_options(help);
    EXPECT_FALSE(options.empty()) << "no options parsed from `" << sub << " --help`";
    for (const std::string& o : options) {
      if (o == "--help") continue;
      ++checked;
      EXPECT_NE(readme.find(o), std::string::npos)
          << "`quadsketch-cli " << sub << "` option " << o << " is not in README.md";
    }
  }
  EXPECT_GT(checked, 40);
}

}  // namespace
}  // namespace qs
