// The proxy devices (device.h): the trajectory file's playback and its errors, the sweep.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include <shapedb/haptics/device.h>

namespace shapedb::haptics {
namespace {

using core::Vec3;

TEST(Device, CsvPlaybackInterpolatesAndHoldsTheEnds) {
  const auto path =
      std::filesystem::temp_directory_path() / ("shapedb-trajectory-" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(path);
    out << "t,x,y,z\n0,0,0,0\n\n1, 1, 2, 3\r\n3,1,2,-1\n";
  }
  Result<TrajectoryDevice> device = TrajectoryDevice::fromCsv(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(device.ok()) << device.error().message;
  EXPECT_EQ(device->keyframes().size(), 3u);
  EXPECT_LT((device->position(0.5) - Vec3(0.5, 1.0, 1.5)).norm(), 1e-15);
  EXPECT_LT((device->position(2.0) - Vec3(1.0, 2.0, 1.0)).norm(), 1e-15);
  EXPECT_LT((device->position(-1.0) - Vec3::Zero()).norm(), 1e-15);
  EXPECT_LT((device->position(10.0) - Vec3(1.0, 2.0, -1.0)).norm(), 1e-15);
  EXPECT_LT((device->position(0.25) - Vec3(0.25, 0.5, 0.75)).norm(), 1e-15);  // back in time
  device->applyForce(0.0, Vec3(1, 2, 3));
  EXPECT_EQ(device->lastForce(), Vec3(1, 2, 3));
}

TEST(Device, CsvErrorsNameTheFileAndLine) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto write = [&](const std::string& name, const std::string& text) {
    const auto path = dir / (name + std::to_string(::getpid()) + ".csv");
    std::ofstream(path) << text;
    return path;
  };
  const auto bad = write("shapedb-bad-", "t,x,y,z\n0,0,0,0\n1,2,x,3\n");
  Result<TrajectoryDevice> r = TrajectoryDevice::fromCsv(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kParse);
  EXPECT_NE(r.error().message.find(bad.string() + ":3:"), std::string::npos) << r.error().message;
  const auto back = write("shapedb-back-", "0,0,0,0\n1,0,0,0\n0.5,0,0,0\n");
  r = TrajectoryDevice::fromCsv(back);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("back in time"), std::string::npos) << r.error().message;
  const auto empty = write("shapedb-empty-", "t,x,y,z\n");
  r = TrajectoryDevice::fromCsv(empty);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(empty.string()), std::string::npos) << r.error().message;
  EXPECT_EQ(TrajectoryDevice::fromCsv(dir / "shapedb-no-such-file.csv").error().code, ErrorCode::kIo);
  for (const auto& p : {bad, back, empty})
    std::filesystem::remove(p);
}

TEST(Device, SweepRunsEveryLaneAcrossTheBoxAtItsSpeed) {
  // Lanes 4 m long, 1 m apart, at 2 m/s: 2 s a lane, 0.5 s between lanes.
  TrajectoryDevice sweep = TrajectoryDevice::sweep(Vec3(0, 0, 0), Vec3(4, 2, 1), 3, 2.0);
  EXPECT_LT((sweep.position(0.0) - Vec3(0, 0, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(1.0) - Vec3(2, 0, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(2.25) - Vec3(4, 0.5, 0.5)).norm(), 1e-15);  // moving to the next lane
  EXPECT_LT((sweep.position(3.5) - Vec3(2, 1, 0.5)).norm(), 1e-15);     // second lane, coming back
  EXPECT_LT((sweep.position(7.0) - Vec3(4, 2, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(100.0) - Vec3(4, 2, 0.5)).norm(), 1e-15);
}

}  // namespace
}  // namespace shapedb::haptics
