#include <regex>

#include <gtest/gtest.h>

#include <shapedb/volume/openvdb_runtime.h>

namespace shapedb::volume {
namespace {

TEST(OpenVdbRuntime, InitializesOnceAndReportsItsVersion) {
  initializeOpenVdb();
  initializeOpenVdb();
  EXPECT_TRUE(std::regex_match(openVdbVersion(), std::regex(R"(\d+\.\d+\.\d+)"))) << openVdbVersion();
}

}  // namespace
}  // namespace shapedb::volume
