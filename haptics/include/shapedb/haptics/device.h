#pragma once

// The haptic proxy: where the device's tip is, and where the force goes. A real device (a Phantom, a
// Falcon) implements ProxyDevice over its driver; shapedb ships a scripted trajectory and CSV playback,
// which is what tests and benchmarks need.

#include <filesystem>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/types.h>

namespace shapedb::haptics {

/// Called from the haptic thread only, once per tick: must not allocate, lock or block.
class ProxyDevice {
 public:
  virtual ~ProxyDevice() = default;
  /// The proxy's position at `seconds` since the loop started, world frame, metres.
  virtual core::Vec3 position(double seconds) = 0;
  /// The force the loop computed for the proxy (newtons, world frame) at that tick.
  virtual void applyForce(double seconds, const core::Vec3& force) = 0;
};

/// A proxy that follows keyframes (time, position), linearly interpolated, holding the first position
/// before the first keyframe and the last after the last. Forces are kept as the last one received.
class TrajectoryDevice final : public ProxyDevice {
 public:
  struct Keyframe {
    double seconds = 0.0;
    core::Vec3 position = core::Vec3::Zero();
  };
  /// Errors: kInvalidArgument for no keyframes, a non-finite value, or times that decrease.
  static Result<TrajectoryDevice> fromKeyframes(std::vector<Keyframe> keyframes);
  /// CSV playback: one keyframe per line, "t,x,y,z" (seconds, metres); a header line and blank lines
  /// are skipped. Errors: kIo, or kParse naming the file and line.
  static Result<TrajectoryDevice> fromCsv(const std::filesystem::path& path);
  /// A back-and-forth sweep through a box at the height of its centre, at `speed` m/s: `lanes` passes
  /// along x (lanes ≥ 1), evenly spaced over the box's y extent, joined by moves along y. It starts at
  /// boxMin's x and y, at time 0, and holds its last position once done.
  static TrajectoryDevice sweep(const core::Vec3& boxMin, const core::Vec3& boxMax, int lanes, double speed);

  core::Vec3 position(double seconds) override;
  void applyForce(double seconds, const core::Vec3& force) override;

  const std::vector<Keyframe>& keyframes() const { return mKeyframes; }
  const core::Vec3& lastForce() const { return mLastForce; }

 private:
  explicit TrajectoryDevice(std::vector<Keyframe> keyframes) : mKeyframes(std::move(keyframes)) {}
  std::vector<Keyframe> mKeyframes;
  std::size_t mCursor = 0;  ///< the segment last used: ticks move forward, so the search starts here
  core::Vec3 mLastForce = core::Vec3::Zero();
};

}  // namespace shapedb::haptics
