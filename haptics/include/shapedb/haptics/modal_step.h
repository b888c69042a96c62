#pragma once

// Exact time stepping of one vibration mode. In mass-normalized modal coordinates every mode is a damped
// oscillator q̈ + 2ζω q̇ + ω² q = f. Over a step h with f held constant (the force a haptic tick computes),
// its state advances exactly by
//   [q, q̇](t + h) = Φ(h) [q, q̇](t) + Γ(h) f,   Φ = e^{Ah},  Γ = A⁻¹ (Φ − I) [0, 1]ᵀ,
// with A = [[0, 1], [−ω², −2ζω]]: no step-size limit, no numerical damping, any ζ ≥ 0 (under-, critically
// and over-damped alike). A stiff steel mode at 20 kHz is stepped at 1 kHz as exactly as a slow one.

namespace shapedb::haptics {

struct ModeStep {
  double a11 = 1.0, a12 = 0.0, a21 = 0.0, a22 = 1.0;  ///< Φ(h)
  double b1 = 0.0, b2 = 0.0;                          ///< Γ(h)

  /// Advances (q, v) = (q, q̇) by one step under the constant force f.
  void advance(double& q, double& v, double f) const {
    const double q1 = a11 * q + a12 * v + b1 * f;
    v = a21 * q + a22 * v + b2 * f;
    q = q1;
  }
};

/// The exact step of a mode of angular frequency `omega` (rad/s, > 0) and damping ratio `zeta` (≥ 0) over
/// `h` seconds (≥ 0).
ModeStep exactModeStep(double omega, double zeta, double h);

}  // namespace shapedb::haptics
