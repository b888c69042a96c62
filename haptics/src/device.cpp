#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string>

#include <shapedb/haptics/device.h>

namespace shapedb::haptics {

using core::Vec3;

Result<TrajectoryDevice> TrajectoryDevice::fromKeyframes(std::vector<Keyframe> keyframes) {
  if (keyframes.empty())
    return Error{ErrorCode::kInvalidArgument, "a trajectory needs at least one keyframe"};
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    const Keyframe& k = keyframes[i];
    if (!std::isfinite(k.seconds) || !k.position.allFinite())
      return Error{ErrorCode::kInvalidArgument, "keyframe " + std::to_string(i + 1) + " is not finite"};
    if (i > 0 && k.seconds < keyframes[i - 1].seconds)
      return Error{ErrorCode::kInvalidArgument,
                   "keyframe " + std::to_string(i + 1) + " goes back in time (times must not decrease)"};
  }
  return TrajectoryDevice(std::move(keyframes));
}

Result<TrajectoryDevice> TrajectoryDevice::fromCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return Error{ErrorCode::kIo, path.string() + ": cannot open the trajectory"};
  std::vector<Keyframe> keyframes;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double values[4];
    const char* cursor = line.data();
    const char* const end = line.data() + line.size();
    bool parsed = true;
    for (int i = 0; i < 4 && parsed; ++i) {
      while (cursor < end && (*cursor == ' ' || *cursor == '\t'))
        ++cursor;
      const auto [next, ec] = std::from_chars(cursor, end, values[i]);
      parsed = ec == std::errc();
      cursor = next;
      while (cursor < end && (*cursor == ' ' || *cursor == '\t' || *cursor == '\r'))
        ++cursor;
      if (parsed && i < 3) parsed = cursor < end && *cursor++ == ',';
    }
    if (parsed && cursor != end) parsed = false;
    if (!parsed) {
      if (keyframes.empty() && number == 1) continue;  // a header ("t,x,y,z")
      return Error{ErrorCode::kParse, path.string() + ":" + std::to_string(number) +
                                          ": expected 't,x,y,z' (seconds, metres), got '" + line + "'"};
    }
    keyframes.push_back({values[0], Vec3(values[1], values[2], values[3])});
  }
  Result<TrajectoryDevice> device = fromKeyframes(std::move(keyframes));
  if (!device) return withContext(device.error(), path.string());
  return device;
}

TrajectoryDevice TrajectoryDevice::sweep(const Vec3& boxMin, const Vec3& boxMax, int lanes, double speed) {
  lanes = std::max(lanes, 1);
  const double z = 0.5 * (boxMin.z() + boxMax.z());
  std::vector<Keyframe> keyframes;
  double t = 0.0;
  for (int lane = 0; lane < lanes; ++lane) {
    const double y = lanes == 1 ? 0.5 * (boxMin.y() + boxMax.y())
                                : boxMin.y() + (boxMax.y() - boxMin.y()) * lane / (lanes - 1);
    const bool forward = lane % 2 == 0;
    const Vec3 from(forward ? boxMin.x() : boxMax.x(), y, z), to(forward ? boxMax.x() : boxMin.x(), y, z);
    if (!keyframes.empty()) t += (from - keyframes.back().position).norm() / speed;
    keyframes.push_back({t, from});
    t += (to - from).norm() / speed;
    keyframes.push_back({t, to});
  }
  return TrajectoryDevice(std::move(keyframes));
}

Vec3 TrajectoryDevice::position(double seconds) {
  const std::size_t n = mKeyframes.size();
  if (seconds <= mKeyframes.front().seconds) return mKeyframes.front().position;
  if (seconds >= mKeyframes.back().seconds) return mKeyframes.back().position;
  if (mKeyframes[mCursor].seconds > seconds) mCursor = 0;  // time went back: search from the start
  while (mCursor + 1 < n && mKeyframes[mCursor + 1].seconds <= seconds)
    ++mCursor;
  const Keyframe& a = mKeyframes[mCursor];
  const Keyframe& b = mKeyframes[std::min(mCursor + 1, n - 1)];
  const double span = b.seconds - a.seconds;
  const double t = span > 0.0 ? (seconds - a.seconds) / span : 1.0;
  return a.position + t * (b.position - a.position);
}

void TrajectoryDevice::applyForce(double /*seconds*/, const Vec3& force) {
  mLastForce = force;
}

}  // namespace shapedb::haptics
