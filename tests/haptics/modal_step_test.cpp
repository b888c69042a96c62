// The exact modal step against the closed-form damped oscillator.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <shapedb/haptics/modal_step.h>

namespace shapedb::haptics {
namespace {

/// Free response x(t) of q̈ + 2ζω q̇ + ω² q = 0 from q = 0, q̇ = 1 (a unit impulse at rest).
double impulseResponse(double omega, double zeta, double t) {
  if (zeta < 1.0) {
    const double wd = omega * std::sqrt(1.0 - zeta * zeta);
    return std::exp(-zeta * omega * t) * std::sin(wd * t) / wd;
  }
  if (zeta == 1.0) return t * std::exp(-omega * t);
  const double s = omega * std::sqrt(zeta * zeta - 1.0);
  return (std::exp((-zeta * omega + s) * t) - std::exp((-zeta * omega - s) * t)) / (2.0 * s);
}

/// Response to a unit force switched on at t = 0, from rest: 1/ω² minus the free decay that meets it.
double stepResponse(double omega, double zeta, double t) {
  if (t <= 0.0) return 0.0;
  // x = (1 − y(t)) / ω², with y the free response from y = 1, ẏ = 0.
  const double w2 = omega * omega;
  if (zeta < 1.0) {
    const double wd = omega * std::sqrt(1.0 - zeta * zeta);
    return (1.0 - std::exp(-zeta * omega * t) * (std::cos(wd * t) + zeta * omega / wd * std::sin(wd * t))) /
           w2;
  }
  if (zeta == 1.0) return (1.0 - std::exp(-omega * t) * (1.0 + omega * t)) / w2;
  const double s = omega * std::sqrt(zeta * zeta - 1.0);
  const double r1 = -zeta * omega + s, r2 = -zeta * omega - s;
  return (1.0 - (r2 * std::exp(r1 * t) - r1 * std::exp(r2 * t)) / (r2 - r1)) / w2;
}

struct Case {
  double hz, zeta;
};
constexpr Case kCases[] = {{50.0, 0.0},  {50.0, 0.02}, {300.0, 0.5},
                           {120.0, 1.0}, {80.0, 3.0},  {4000.0, 0.01}};

TEST(ModalStep, ImpulseResponseMatchesTheAnalyticDampedOscillator) {
  const double h = 1e-3;
  for (const Case& c : kCases) {
    const double omega = 2.0 * std::numbers::pi * c.hz;
    const ModeStep step = exactModeStep(omega, c.zeta, h);
    double q = 0.0, v = 1.0;
    double peak = 0.0, worst = 0.0;
    for (int k = 1; k <= 2000; ++k) {
      step.advance(q, v, 0.0);
      const double exact = impulseResponse(omega, c.zeta, k * h);
      peak = std::max(peak, std::abs(exact));
      worst = std::max(worst, std::abs(q - exact));
    }
    EXPECT_LT(worst, 1e-9 * peak) << c.hz << " Hz, ζ = " << c.zeta;
  }
}

TEST(ModalStep, ForceHeldOverOneTickMatchesTheDifferenceOfTwoStepResponses) {
  // A force f over [0, h), then none: x(t) = f (s(t) − s(t − h)); a tick's contact force is exactly this.
  const double h = 1e-3, f = 3.5;
  for (const Case& c : kCases) {
    const double omega = 2.0 * std::numbers::pi * c.hz;
    const ModeStep step = exactModeStep(omega, c.zeta, h);
    double q = 0.0, v = 0.0, peak = 0.0, worst = 0.0;
    for (int k = 1; k <= 500; ++k) {
      step.advance(q, v, k == 1 ? f : 0.0);
      const double t = k * h;
      const double exact = f * (stepResponse(omega, c.zeta, t) - stepResponse(omega, c.zeta, t - h));
      peak = std::max(peak, std::abs(exact));
      worst = std::max(worst, std::abs(q - exact));
    }
    EXPECT_LT(worst, 1e-8 * peak) << c.hz << " Hz, ζ = " << c.zeta;
  }
}

TEST(ModalStep, ConstantForceSettlesAtTheStaticDeflection) {
  const double omega = 2.0 * std::numbers::pi * 20.0, zeta = 0.1, f = -2.0;
  const ModeStep step = exactModeStep(omega, zeta, 1e-3);
  double q = 0.0, v = 0.0;
  for (int k = 0; k < 5000; ++k)
    step.advance(q, v, f);
  EXPECT_NEAR(q, f / (omega * omega), 1e-12);
  EXPECT_NEAR(v, 0.0, 1e-9);
}

TEST(ModalStep, AModeFarAboveTheTickRateStaysExactAndBounded) {
  // 20 kHz stepped at 1 kHz: ωh ≈ 126. An explicit integrator explodes; the exact step does not.
  const double omega = 2.0 * std::numbers::pi * 20000.0, zeta = 0.001, h = 1e-3;
  const ModeStep step = exactModeStep(omega, zeta, h);
  double q = 0.0, v = 1.0;
  for (int k = 1; k <= 100; ++k) {
    step.advance(q, v, 0.0);
    EXPECT_NEAR(q, impulseResponse(omega, zeta, k * h), 1e-9 / omega) << k;
  }
}

}  // namespace
}  // namespace shapedb::haptics
