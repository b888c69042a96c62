#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <shapedb/core/sound.h>

namespace shapedb::core {

Result<ImpactPoint> chooseImpact(const TriangleMesh& mesh, const Vec3& center,
                                 const std::optional<Vec3>& near) {
  if (mesh.vertices.empty()) return Error{ErrorCode::kEmptyMesh, "mesh has no vertices"};
  const Vec3 target = near.value_or(center);
  ImpactPoint out;
  double best = near ? std::numeric_limits<double>::infinity() : -1.0;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const double d = (mesh.vertices[v] - target).squaredNorm();
    if (near ? d < best : d > best) {
      best = d;
      out.vertex = v;
    }
  }
  Vec3 normal = Vec3::Zero();
  for (const auto& t : mesh.triangles)
    if (t[0] == out.vertex || t[1] == out.vertex || t[2] == out.vertex)
      normal += (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
  if (normal.squaredNorm() > 0.0) out.direction = -normal.normalized();
  return out;
}

Result<ImpactSound> synthesizeImpact(const AdaptedPhysics& physics, const TetLocation& at,
                                     const Vec3& direction, const ImpactSoundOptions& options) {
  if (options.sampleRate < 8000 || options.sampleRate > 192000)
    return Error{ErrorCode::kInvalidArgument,
                 "the sample rate must be 8,000 to 192,000 Hz, not " + std::to_string(options.sampleRate)};
  if (!(options.seconds > 0.0 && options.seconds <= 60.0))
    return Error{ErrorCode::kInvalidArgument, "the sound must last more than 0 and at most 60 s"};
  if (!(direction.norm() > 0.0) || !direction.allFinite())
    return Error{ErrorCode::kInvalidArgument, "the impulse needs a direction"};
  if (at.tet >= physics.tetMesh.tets.size())
    return Error{ErrorCode::kInvalidArgument, "the impact point is not in the tet mesh"};
  const Vec3 d = direction.normalized();
  const Eigen::VectorXd frequencies = physics.frequenciesHz();
  const Eigen::VectorXd zeta = physics.dampingRatios();
  const double limit = std::min(options.maxFrequencyHz, 0.5 * options.sampleRate);

  ImpactSound sound;
  sound.sampleRate = options.sampleRate;
  std::vector<double> gains;
  for (int i = 0; i < frequencies.size(); ++i) {
    if (!(frequencies[i] < limit) || !(zeta[i] < 1.0)) continue;  // inaudible, or overdamped: no ring
    double g = 0.0;
    for (int k = 0; k < 4; ++k) {
      const auto node = static_cast<Eigen::Index>(physics.tetMesh.tets[at.tet][static_cast<std::size_t>(k)]);
      g += at.weights[static_cast<std::size_t>(k)] * physics.modeShapes.block<3, 1>(3 * node, i).dot(d);
    }
    sound.modes.push_back(i);
    gains.push_back(g);
  }
  if (sound.modes.empty())
    return Error{ErrorCode::kInvalidArgument,
                 "no mode rings below " + std::to_string(static_cast<long>(limit)) +
                     " Hz (the lowest is at " +
                     std::to_string(static_cast<long>(frequencies.size() ? frequencies[0] : 0.0)) +
                     " Hz): a larger object, a softer material, or a higher sample rate"};
  sound.frequenciesHz.resize(static_cast<Eigen::Index>(sound.modes.size()));
  sound.gains = Eigen::Map<const Eigen::VectorXd>(gains.data(), static_cast<Eigen::Index>(gains.size()));

  const auto n = static_cast<std::size_t>(std::ceil(options.seconds * options.sampleRate));
  std::vector<double> velocity(n, 0.0);
  for (std::size_t m = 0; m < sound.modes.size(); ++m) {
    const int i = sound.modes[m];
    sound.frequenciesHz[static_cast<Eigen::Index>(m)] = frequencies[i];
    const double omega = 2.0 * std::numbers::pi * frequencies[i];
    const double decay = zeta[i] * omega;
    const double omegaD = omega * std::sqrt(1.0 - zeta[i] * zeta[i]);
    for (std::size_t s = 0; s < n; ++s) {
      const double t = static_cast<double>(s) / options.sampleRate;
      velocity[s] +=
          gains[m] * std::exp(-decay * t) * (std::cos(omegaD * t) - decay / omegaD * std::sin(omegaD * t));
    }
  }
  double peak = 0.0;
  for (double v : velocity)
    peak = std::max(peak, std::abs(v));
  sound.scale = peak > 0.0 ? 0.9 / peak : 0.0;
  sound.samples.resize(n);
  for (std::size_t s = 0; s < n; ++s)
    sound.samples[s] = static_cast<float>(sound.scale * velocity[s]);
  return sound;
}

}  // namespace shapedb::core
