#include <cmath>

#include <shapedb/haptics/modal_step.h>

namespace shapedb::haptics {

ModeStep exactModeStep(double omega, double zeta, double h) {
  // With σ = −ζω, the matrix N = A − σI = [[ζω, 1], [−ω², −ζω]] squares to μI, μ = ω²(ζ² − 1). So
  // e^{Ah} = e^{σh} (C I + S N) with C = cosh(√μ h), S = sinh(√μ h)/√μ for μ > 0 (over-damped),
  // cos and sin of √−μ h for μ < 0 (under-damped), C = 1, S = h at μ = 0 (critical).
  const double sigma = -zeta * omega;
  const double mu = omega * omega * (zeta * zeta - 1.0);
  double eC = 0.0, eS = 0.0;  // e^{σh} C and e^{σh} S
  if (mu > 0.0) {
    // Written with the two exponents σ ± √μ (both ≤ 0), which cannot overflow where cosh alone would.
    const double s = std::sqrt(mu);
    const double ePlus = std::exp((sigma + s) * h), eMinus = std::exp((sigma - s) * h);
    eC = 0.5 * (ePlus + eMinus);
    eS = s * h > 1e-8 ? 0.5 * (ePlus - eMinus) / s : std::exp(sigma * h) * h;
  } else {
    const double e = std::exp(sigma * h);
    if (mu < 0.0) {
      const double s = std::sqrt(-mu);
      eC = e * std::cos(s * h);
      eS = s * h > 1e-8 ? e * std::sin(s * h) / s : e * h;
    } else {
      eC = e;
      eS = e * h;
    }
  }
  ModeStep step;
  step.a11 = eC + eS * zeta * omega;
  step.a12 = eS;
  step.a21 = -eS * omega * omega;
  step.a22 = eC - eS * zeta * omega;
  // Γ = A⁻¹ (Φ − I) [0, 1]ᵀ with A⁻¹ = [[−2ζ/ω, −1/ω²], [1, 0]].
  step.b1 = -2.0 * zeta / omega * step.a12 - (step.a22 - 1.0) / (omega * omega);
  step.b2 = step.a12;
  return step;
}

}  // namespace shapedb::haptics
