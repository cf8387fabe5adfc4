// README's parameter table against param_table(): the same keys in the same
// order, the same defaults and the same meanings. The README is read as
// text, so a row added, dropped or edited on either side fails here.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "vasco_gpu/params.h"

namespace vasco {
namespace {

struct ReadmeRow {
  std::string key, meaning, default_text;
};

std::string trim(const std::string &s) {
  const size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::string unquote(const std::string &s) {
  return s.size() >= 2 && s.front() == '`' && s.back() == '`' ? s.substr(1, s.size() - 2) : s;
}

// The rows "| `vasco_KEY` | meaning | default | valid |" of README.md.
std::vector<ReadmeRow> readme_rows() {
  std::ifstream in(std::string(VASCO_LOGS_DIR) + "/../README.md");
  std::vector<ReadmeRow> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| `vasco_", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream s(line.substr(1));
    std::string cell;
    while (std::getline(s, cell, '|')) cells.push_back(trim(cell));
    if (cells.size() >= 3) rows.push_back({unquote(cells[0]), cells[1], cells[2]});
  }
  return rows;
}

// A default as the README writes it: a number, or "all" for -1.
double readme_default(const std::string &text) { return text == "all" ? -1.0 : std::stod(text); }

TEST(ParamReadme, EveryKeyDefaultAndMeaningAgreesWithTheTable) {
  const std::vector<ReadmeRow> rows = readme_rows();
  const std::vector<ParamSpec> &table = param_table();
  ASSERT_FALSE(rows.empty()) << "README.md has no parameter table";
  EXPECT_EQ(rows.size(), table.size());
  for (size_t i = 0; i < std::min(rows.size(), table.size()); ++i) {
    SCOPED_TRACE(rows[i].key);
    EXPECT_EQ(rows[i].key, table[i].key);
    EXPECT_EQ(rows[i].meaning, table[i].meaning);
    EXPECT_EQ(readme_default(rows[i].default_text), table[i].default_value);
  }
}

}  // namespace
}  // namespace vasco
