// docs/architecture.md's stage table names headers, functions and tests that exist: a newcomer who
// follows it finds what it says.

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace shapedb {
namespace {

std::string readWhole(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(Docs, TheStageTableNamesHeadersFunctionsAndTestsThatExist) {
  const std::string root = SHAPEDB_SOURCE_DIR;
  const std::string doc = readWhole(root + "/docs/architecture.md");
  const std::size_t begin = doc.find("<!-- stage-table -->");
  const std::size_t end = doc.find("<!-- /stage-table -->");
  ASSERT_NE(begin, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  std::istringstream table(doc.substr(begin, end - begin));
  const std::regex code("`([^`]+)`");
  int rows = 0;
  for (std::string line; std::getline(table, line);) {
    if (line.rfind("| ", 0) != 0 || line.rfind("| stage", 0) == 0) continue;
    std::vector<std::string> cells;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), code); it != std::sregex_iterator(); ++it)
      cells.push_back((*it)[1]);
    SCOPED_TRACE(line);
    ASSERT_GE(cells.size(), 4u);
    const std::string header = readWhole(root + "/" + cells[0]);
    EXPECT_FALSE(header.empty()) << cells[0] << " does not exist";
    EXPECT_NE(header.find(" " + cells[1] + "("), std::string::npos) << cells[1] << " is not in " << cells[0];
    const std::string test = readWhole(root + "/" + cells[2]);
    EXPECT_FALSE(test.empty()) << cells[2] << " does not exist";
    const std::size_t dot = cells[3].find('.');
    ASSERT_NE(dot, std::string::npos) << cells[3];
    const std::string name = cells[3].substr(0, dot) + ", " + cells[3].substr(dot + 1) + ")";
    EXPECT_NE(test.find(name), std::string::npos) << cells[3] << " is not in " << cells[2];
    ++rows;
  }
  EXPECT_GE(rows, 10);
}

}  // namespace
}  // namespace shapedb
