#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include <shapedb/core/adapt.h>

namespace shapedb::core {

Placement placementOf(const Normalization& query, const Mat3& orientation) {
  return {query.principalAxes * orientation.transpose(), query.meshFromCanonical.topRightCorner<3, 1>(),
          1.0 / query.scale};
}

Eigen::VectorXd AdaptedPhysics::frequenciesHz() const {
  return eigenvalues.cwiseSqrt() / (2.0 * std::numbers::pi);
}

Eigen::VectorXd AdaptedPhysics::dampingRatios() const {
  Eigen::VectorXd z(eigenvalues.size());
  for (Eigen::Index i = 0; i < z.size(); ++i)
    z[i] = damping.dampingRatio(std::sqrt(eigenvalues[i]));
  return z;
}

Result<AdaptedPhysics> adapt(const PhysicalData& entry, const Normalization& query,
                             const MassProperties& queryMass, const Mat3& orientation,
                             const Material& material, const RayleighDamping& damping,
                             const StretchBasis* stretch) {
  if (Status valid = validateMaterial(material); !valid) return valid.error();
  const std::size_t nodes = entry.tetMesh.nodeCount();
  if (entry.modes.shapes.rows() != static_cast<Eigen::Index>(3 * nodes) ||
      entry.modes.shapes.cols() != entry.modes.eigenvalues.size())
    return Error{ErrorCode::kInvalidArgument, "entry's mode shapes do not fit its tet mesh"};

  AdaptedPhysics out;
  out.material = material;
  out.placement = placementOf(query, orientation);
  out.damping = damping;
  const Placement& P = out.placement;
  const double L = P.scale, rho = material.density;

  out.tetMesh.tets = entry.tetMesh.tets;
  out.tetMesh.nodes.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i)
    out.tetMesh.nodes[i] = P.toQuery(entry.tetMesh.nodes[i]);

  out.massProperties = queryMass;
  out.massProperties.density = rho;
  out.massProperties.mass = rho * queryMass.volume;
  out.massProperties.inertia = queryMass.inertia * (rho / queryMass.density);

  // Mass scales with ρL³, inertia with ρL⁵, both rotated into the query's frame.
  const MassProperties& e = entry.massProperties;
  out.entryMassProperties = e;
  out.entryMassProperties.density = rho;
  out.entryMassProperties.volume = e.volume * L * L * L;
  out.entryMassProperties.mass = rho * out.entryMassProperties.volume;
  out.entryMassProperties.area = e.area * L * L;
  out.entryMassProperties.centerOfMass = P.toQuery(e.centerOfMass);
  out.entryMassProperties.inertia =
      P.rotation * e.inertia * P.rotation.transpose() * (rho / e.density) * std::pow(L, 5);

  // The entry's modes, or those of the entry stretched to the query's second moments (in the entry's
  // axes: the query's canonical frame is Oᵀ times the entry's).
  const Eigen::VectorXd* eigenvalues = &entry.modes.eigenvalues;
  const Eigen::MatrixXd* shapes = &entry.modes.shapes;
  std::optional<StretchedModes> stretched;
  if (stretch) {
    const Mat3 target =
        orientation * covarianceFromInertia(query.canonicalMoments.asDiagonal()) * orientation.transpose();
    Result<StretchedModes> s = stretchModes(*stretch, entry.modes, entry.tetMesh,
                                            momentMatchingStretch(stretch->secondMoments, target));
    if (s) {
      stretched = std::move(s).value();
      eigenvalues = &stretched->eigenvalues;
      shapes = &stretched->shapes;
      out.stretch = stretched->stretch;
    } else {
      out.warnings.push_back("stretch correction not applied: " + s.error().message);
    }
  }

  // K scales with E·L, M with ρ·L³: λ = (E / ρL²) λ'. φ keeps φᵀMφ = 1 with φ = R φ' / sqrt(ρL³).
  out.eigenvalues = *eigenvalues * (material.youngsModulus / (rho * L * L));
  const double shapeScale = 1.0 / std::sqrt(rho * L * L * L);
  const Eigen::Index m = shapes->cols();
  out.modeShapes.resize(shapes->rows(), m);
  const Mat3 R = P.rotation * shapeScale;
  for (Eigen::Index j = 0; j < m; ++j)
    for (std::size_t i = 0; i < nodes; ++i)
      out.modeShapes.col(j).segment<3>(3 * static_cast<Eigen::Index>(i)) =
          R * shapes->col(j).segment<3>(3 * static_cast<Eigen::Index>(i));

  out.collision = entry.collision;
  for (CollisionShape& s : out.collision.shapes) {
    s.center = P.toQuery(s.center);
    s.rotation = P.rotation * s.rotation;
    s.halfExtents *= L;
    s.radius *= L;
    s.halfLength *= L;
  }

  if (std::abs(material.poissonRatio - entry.modes.poissonRatio) > 0.01)
    out.warnings.push_back("material Poisson ratio " + std::to_string(material.poissonRatio) +
                           " differs from the database's " + std::to_string(entry.modes.poissonRatio) +
                           ": mode shapes and frequency ratios are the database's");
  return out;
}

Eigen::VectorXd blendSpectra(std::span<const SpectrumSample> samples, std::vector<double>* weights) {
  const double nearest = samples.front().distance;
  std::vector<double> w(samples.size(), 0.0);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const double d = samples[k].distance;
    if (nearest <= 0.0)
      w[k] = d <= 0.0 ? 1.0 : 0.0;
    else if (d <= kSpectrumReach * nearest)
      w[k] = 1.0 / d;
  }
  const Eigen::VectorXd& first = *samples.front().eigenvalues;
  Eigen::VectorXd out(first.size());
  for (Eigen::Index i = 0; i < first.size(); ++i) {
    double sum = 0.0, logs = 0.0;
    int blended = 0;
    for (std::size_t k = 0; k < samples.size(); ++k)
      if (w[k] > 0.0 && i < samples[k].eigenvalues->size()) {
        sum += w[k];
        logs += w[k] * std::log((*samples[k].eigenvalues)[i]);
        ++blended;
      }
    out[i] = blended == 1 ? first[i] : std::exp(logs / sum);  // one sample: its own value, unrounded
  }
  if (weights) {
    const double total = std::accumulate(w.begin(), w.end(), 0.0);
    weights->resize(w.size());
    for (std::size_t k = 0; k < w.size(); ++k)
      (*weights)[k] = w[k] / total;
  }
  return out;
}

}  // namespace shapedb::core
