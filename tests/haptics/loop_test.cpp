// The haptic loop: contact and modal response, determinism on a simulated clock, augmentation that never
// holds up a tick, failures reported, and concurrent readers (run under the tsan preset too).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/haptics/loop.h>

#include "synthetic_scene.h"

namespace shapedb::haptics {
namespace {

using core::Vec3;

/// A proxy that starts left of the row of boxes and moves along x through them, at the height of their
/// top faces minus `dip`: it presses into each box it passes.
TrajectoryDevice sweepAlongRow(double length, double seconds, double dip, double size) {
  return *TrajectoryDevice::fromKeyframes({{0.0, Vec3(-0.2, 0.0, 0.5 * size + 0.005 - dip)},
                                           {seconds, Vec3(length, 0.0, 0.5 * size + 0.005 - dip)}});
}

AugmentFunction synthetic() {
  return [](const SceneObject& object) { return test::augmentBox(object); };
}

// A fracture event: every object requested at the first tick, however far the proxy is; without it, an
// object is requested only when the proxy comes near.
TEST(HapticLoop, AFractureEventRequestsEveryObjectAtTheFirstTick) {
  const std::vector<SceneObject> objects = test::boxRow(5, 0.1, 1.0);
  for (const bool burst : {false, true}) {
    SCOPED_TRACE(burst ? "all at once" : "as the proxy comes near");
    auto device = TrajectoryDevice::fromKeyframes({{0.0, Vec3(0.0, 10.0, 0.0)}});  // far from every box
    ASSERT_TRUE(device.ok());
    LoopOptions options;
    options.requestAllAtStart = burst;
    options.simulatedAugmentationSeconds = 0.02;
    auto loop = HapticLoop::create(objects, *device, synthetic(), options);
    ASSERT_TRUE(loop.ok()) << loop.error().message;
    const LoopReport report = (*loop)->simulate(0.1);
    EXPECT_EQ(report.objectsAugmented, burst ? objects.size() : 0u);
    for (const ObjectOutcome& o : report.objects)
      if (burst) {
        EXPECT_EQ(o.state, ObjectOutcome::State::kReady) << o.name;
        EXPECT_NEAR(o.augmentationSeconds, 0.02, 1e-9) << o.name;
      } else {
        EXPECT_EQ(o.state, ObjectOutcome::State::kUntouched) << o.name;
      }
    if (burst) {
      EXPECT_NEAR(report.augmentationMillis.max, 20.0, 1e-6);
    }
  }
}

// The default sweep over a scene covers the objects' bounding box, a lane per typical object width.
TEST(HapticLoop, TheDefaultSweepCrossesTheSceneALanePerObjectWidth) {
  // Three 1 m cubes spread over 6 m along y: lanes of the median width (1 m), six of them.
  std::vector<SceneObject> scene;
  for (double y : {0.5, 3.0, 5.5}) {
    core::TriangleMesh cube = core::makeBox({1.0, 1.0, 1.0});
    for (Vec3& p : cube.vertices)
      p += Vec3(0.5, y, 0.5);
    scene.push_back({"cube", cube});
  }
  TrajectoryDevice sweep = sweepThrough(scene, 2.0);
  EXPECT_LT((sweep.position(0.0) - Vec3(0.0, 0.0, 0.5)).norm(), 1e-12);
  EXPECT_LT((sweep.position(1e6) - Vec3(0.0, 6.0, 0.5)).norm(), 1e-12);  // six lanes: ends at x's start
  // Every keyframe inside the box, at mid height; lanes 1.2 m apart (six over 6 m: five gaps).
  double lastY = 0.0;
  for (const TrajectoryDevice::Keyframe& k : sweep.keyframes()) {
    EXPECT_GE(k.position.x(), -1e-12);
    EXPECT_LE(k.position.x(), 1.0 + 1e-12);
    EXPECT_NEAR(k.position.z(), 0.5, 1e-12);
    if (k.position.y() > lastY + 1e-9) {
      EXPECT_NEAR(k.position.y() - lastY, 1.2, 1e-9);
      lastY = k.position.y();
    }
  }
  EXPECT_NEAR(lastY, 6.0, 1e-9);
}

TEST(HapticLoop, SimulatedRunsAreDeterministicToTheBit) {
  const auto objects = test::boxRow(4, 0.1, 0.3);
  LoopOptions options;
  options.recordForces = true;
  std::vector<std::vector<Vec3>> traces;
  for (int run = 0; run < 2; ++run) {
    TrajectoryDevice device = sweepAlongRow(1.2, 2.0, 0.002, 0.1);
    auto loop = HapticLoop::create(objects, device, synthetic(), options);
    ASSERT_TRUE(loop.ok()) << loop.error().message;
    const LoopReport report = (*loop)->simulate(2.0);
    EXPECT_EQ(report.ticks, 2000u);
    EXPECT_EQ(report.objectsAugmented, 4u);
    EXPECT_GT(report.contactTicks, 100u);
    for (const ObjectOutcome& o : report.objects) {
      EXPECT_EQ(o.source, "synthetic-box");
      // Served at the first tick after request + 20 ms: the latency is 20 ms exactly, on the simulated clock.
      EXPECT_NEAR(o.augmentationSeconds, 0.02, 1e-12) << o.name;
    }
    traces.push_back(report.forces);
  }
  ASSERT_EQ(traces[0].size(), 2000u);
  for (std::size_t k = 0; k < traces[0].size(); ++k)
    ASSERT_EQ(traces[0][k], traces[1][k]) << "tick " << k;
}

TEST(HapticLoop, PressingSettlesWhereTheModesBalanceTheContactForce) {
  // The proxy dips 2 mm into the top of a box and stays: the penalty force pushes it up (+z), the reaction
  // deflects the box's modes until each mode's stiffness balances its share: ω²ⱼ qⱼ = φⱼᵀ f.
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  const double top = 0.05, dip = 0.002;
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes({{0.0, Vec3(0.01, 0.02, top + 0.005 - dip)}});
  LoopOptions options;
  options.stiffness = 500.0;
  auto loop = HapticLoop::create(objects, device, synthetic(), options);
  ASSERT_TRUE(loop.ok());
  const LoopReport report = (*loop)->simulate(8.0);
  ASSERT_EQ(report.objectsAugmented, 1u);
  const Vec3 force = device.lastForce();
  EXPECT_NEAR(force.x(), 0.0, 1e-12);
  EXPECT_NEAR(force.y(), 0.0, 1e-12);
  EXPECT_GT(force.z(), 0.0);
  EXPECT_LE(force.z(), options.stiffness * dip);  // the surface gave way a little

  const AugmentedObject& data = *(*loop)->augmentation(0);
  const Eigen::VectorXd q = (*loop)->modalCoordinates(0);
  ASSERT_EQ(q.size(), data.physics.eigenvalues.size());
  // The reaction −f at the contact point, through the tet holding it: modal force φᵀ(−f).
  const Vec3 contactPoint(0.01, 0.02, top);
  const core::TetLocation where = data.locator->locate(contactPoint);
  Eigen::VectorXd modalForce = Eigen::VectorXd::Zero(q.size());
  for (int k = 0; k < 4; ++k)
    for (int a = 0; a < 3; ++a)
      modalForce -= where.weights[k] *
                    data.physics.modeShapes.row(3 * data.physics.tetMesh.tets[where.tet][k] + a).transpose() *
                    force[a];
  const Eigen::VectorXd balance = data.physics.eigenvalues.cwiseProduct(q) - modalForce;
  EXPECT_LT(balance.norm(), 1e-6 * modalForce.norm()) << balance.transpose();
  // And the surface gave way by exactly the penetration the force lost.
  Vec3 moved = Vec3::Zero();
  const Eigen::VectorXd u = data.physics.modeShapes * q;
  for (int k = 0; k < 4; ++k)
    moved += where.weights[k] * u.segment<3>(3 * data.physics.tetMesh.tets[where.tet][k]);
  EXPECT_NEAR(force.z(), options.stiffness * (dip + moved.z()), 1e-9);
  // The deformed surface moved the vertices the modes move, through the linking weights.
  const std::vector<Vec3> deformed = (*loop)->deformedSurface(0);
  ASSERT_EQ(deformed.size(), objects[0].mesh.vertices.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < deformed.size(); ++i)
    largest = std::max(largest, (deformed[i] - objects[0].mesh.vertices[i]).norm());
  EXPECT_GT(largest, 0.0);
  EXPECT_LT(largest, 0.01);
}

TEST(HapticLoop, OneTickOfContactRingsEachModeAsTheAnalyticDampedOscillator) {
  // One tick in contact, then away: mode j was pushed by Qⱼ = φⱼᵀ(−f) for one period h and then rings
  // freely, so qⱼ(t) = Qⱼ (s(t) − s(t − h)) with s the damped oscillator's unit step response.
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  const Vec3 touching(0.01, -0.02, 0.052), away(0.01, -0.02, 0.1);
  struct Switchable final : ProxyDevice {
    Vec3 at;
    Vec3 force = Vec3::Zero();
    Vec3 position(double) override { return at; }
    void applyForce(double, const Vec3& f) override { force = f; }
  } proxy;
  proxy.at = touching;
  LoopOptions options;
  options.simulatedAugmentationSeconds = 0.0;
  auto loop = HapticLoop::create(objects, proxy, synthetic(), options);
  ASSERT_TRUE(loop.ok());
  proxy.at = away;
  (*loop)->tick(0.0);  // too far to touch, near enough to be augmented
  (*loop)->simulate(0.002);
  ASSERT_NE((*loop)->augmentation(0), nullptr);
  ASSERT_EQ((*loop)->modalCoordinates(0).norm(), 0.0);

  proxy.at = touching;
  const Vec3 f = (*loop)->tick(1.0);
  ASSERT_GT(f.z(), 0.0);
  proxy.at = away;
  const AugmentedObject& data = *(*loop)->augmentation(0);
  const core::TetLocation where = data.locator->locate(Vec3(touching.x(), touching.y(), 0.05));
  const Eigen::Index modes = data.physics.eigenvalues.size();
  Eigen::VectorXd modalForce = Eigen::VectorXd::Zero(modes);
  for (int k = 0; k < 4; ++k)
    for (int a = 0; a < 3; ++a)
      modalForce -= where.weights[k] *
                    data.physics.modeShapes.row(3 * data.physics.tetMesh.tets[where.tet][k] + a).transpose() *
                    f[a];
  const Eigen::VectorXd zeta = data.physics.dampingRatios();
  const double h = 1.0 / options.rateHz;
  const auto step = [](double omega, double z, double t) {  // under-damped unit step response
    if (t <= 0.0) return 0.0;
    const double wd = omega * std::sqrt(1.0 - z * z);
    return (1.0 - std::exp(-z * omega * t) * (std::cos(wd * t) + z * omega / wd * std::sin(wd * t))) /
           (omega * omega);
  };
  for (int n = 1; n <= 40; ++n) {
    if (n > 1) (*loop)->tick(1.0 + (n - 1) * h);
    const Eigen::VectorXd q = (*loop)->modalCoordinates(0);
    for (Eigen::Index j = 0; j < modes; ++j) {
      const double omega = std::sqrt(data.physics.eigenvalues[j]), t = n * h;
      const double exact = modalForce[j] * (step(omega, zeta[j], t) - step(omega, zeta[j], t - h));
      EXPECT_NEAR(q[j], exact, 1e-9 * std::abs(modalForce[j]) / (omega * omega))
          << "mode " << j << ", tick " << n;
    }
  }
}

TEST(HapticLoop, ReleasedObjectRingsDownAndComesToRest) {
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  // In for 50 ms, then away.
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes(
      {{0.0, Vec3(0, 0, 0.053)}, {0.05, Vec3(0, 0, 0.053)}, {0.051, Vec3(0, 0, 0.2)}});
  LoopOptions options;
  options.simulatedAugmentationSeconds = 0.0;
  auto loop = HapticLoop::create(objects, device, synthetic(), options);
  ASSERT_TRUE(loop.ok());
  (*loop)->simulate(0.06);
  EXPECT_GT((*loop)->modalCoordinates(0).norm(), 0.0);  // ringing after the release
  (*loop)->simulate(10.0);                              // α = 2/s: the slowest mode loses 80 dB in about 9 s
  EXPECT_EQ((*loop)->modalCoordinates(0).norm(), 0.0);
}

TEST(HapticLoop, TicksGoOnWhileAnAugmentationIsUnderWay) {
  // The augmentation of the only object cannot finish before the loop has ticked on for 150 ms of its
  // clock: a loop that waited for its workers would never get there (and the worker gives up after 5 s).
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  struct WatchingDevice final : ProxyDevice {
    std::atomic<double> latest{0.0};
    Vec3 position(double seconds) override {
      latest.store(seconds, std::memory_order_release);
      return Vec3(0, 0, 0.06);
    }
    void applyForce(double, const Vec3&) override {}
  } device;
  std::atomic<bool> sawTicks{false};
  AugmentFunction slow = [&](const SceneObject& object) {
    const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (device.latest.load(std::memory_order_acquire) < 0.15 && std::chrono::steady_clock::now() < giveUp)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    sawTicks = device.latest.load(std::memory_order_acquire) >= 0.15;
    return test::augmentBox(object);
  };
  auto loop = HapticLoop::create(objects, device, slow, {});
  ASSERT_TRUE(loop.ok());
  const LoopReport report = (*loop)->run(0.4);
  EXPECT_TRUE(sawTicks);
  EXPECT_EQ(report.objectsAugmented, 1u);
  EXPECT_GE(report.objects[0].augmentationSeconds, 0.15);
  EXPECT_GT(report.ticks, 0u);
}

TEST(HapticLoop, ConcurrentReadersSeeConsistentDataWhileTheLoopRuns) {
  const auto objects = test::boxRow(12, 0.08, 0.2);
  TrajectoryDevice device = sweepAlongRow(2.4, 0.6, 0.003, 0.08);
  LoopOptions options;
  options.workers = 2;
  options.rateHz = 2000.0;
  auto loop = HapticLoop::create(objects, device, synthetic(), options);
  ASSERT_TRUE(loop.ok());
  std::atomic<bool> done{false};
  std::size_t reads = 0;
  std::thread reader([&] {
    while (!done.load()) {
      for (std::size_t i = 0; i < (*loop)->objectCount(); ++i) {
        const AugmentedObject* a = (*loop)->augmentation(i);  // before the coordinates: it may appear
        const Eigen::VectorXd q = (*loop)->modalCoordinates(i);
        const std::vector<Vec3> surface = (*loop)->deformedSurface(i);
        EXPECT_EQ(surface.size(), objects[i].mesh.vertices.size());
        if (a) {
          EXPECT_EQ(q.size(), a->physics.eigenvalues.size());
        }
        ++reads;
      }
    }
  });
  const LoopReport report = (*loop)->run(0.6);
  done = true;
  reader.join();
  EXPECT_GT(reads, 0u);
  const auto untouched =
      std::count_if(report.objects.begin(), report.objects.end(),
                    [](const ObjectOutcome& o) { return o.state == ObjectOutcome::State::kUntouched; });
  EXPECT_EQ(report.objectsAugmented + report.objectsPending + report.objectsFailed +
                static_cast<std::size_t>(untouched),
            objects.size());
  EXPECT_GT(report.objectsAugmented, 0u);
  EXPECT_EQ(report.objectsFailed, 0u);
  for (const ObjectOutcome& o : report.objects)
    if (o.state == ObjectOutcome::State::kReady) {
      EXPECT_GE(o.augmentationSeconds, 0.0);
    }
  // Finishing the sweep on the simulated clock picks up where the real-time run left off.
  const LoopReport rest = (*loop)->simulate(0.2);
  EXPECT_EQ(rest.objectsPending, 0u);
}

TEST(HapticLoop, FailedAugmentationsAreReportedAndNeverRetried) {
  const auto objects = test::boxRow(3, 0.1, 0.3);
  std::atomic<int> calls{0};
  AugmentFunction augment = [&](const SceneObject& object) -> Result<AugmentedObject> {
    ++calls;
    if (object.name == "box-0")
      return Error{ErrorCode::kNotClosed, "box-0: mesh is not closed (3 boundary edges)"};
    if (object.name == "box-1") throw std::runtime_error("out of cheese");
    Result<AugmentedObject> data = test::augmentBox(object);
    data->physics.modeShapes.conservativeResize(Eigen::NoChange, 2);  // modes that do not fit
    return data;
  };
  TrajectoryDevice device = sweepAlongRow(1.0, 1.0, 0.002, 0.1);
  auto loop = HapticLoop::create(objects, device, augment, {});
  ASSERT_TRUE(loop.ok());
  LoopReport report = (*loop)->simulate(1.0);
  report = (*loop)->simulate(1.0);  // and back over them: no second attempt
  EXPECT_EQ(calls.load(), 3);
  EXPECT_EQ(report.objectsFailed, 3u);
  EXPECT_EQ(report.contactTicks, 0u);
  EXPECT_EQ(report.objects[0].error, "box-0: mesh is not closed (3 boundary edges)");
  EXPECT_EQ(report.objects[1].error, "augmentation threw: out of cheese");
  EXPECT_NE(report.objects[2].error.find("inconsistent"), std::string::npos) << report.objects[2].error;
}

TEST(HapticLoop, CreateRejectsBadOptionsAndEmptyObjects) {
  const auto objects = test::boxRow(1, 0.1, 0.3);
  TrajectoryDevice device = sweepAlongRow(1.0, 1.0, 0.0, 0.1);
  LoopOptions bad;
  bad.rateHz = 0.0;
  EXPECT_EQ(HapticLoop::create(objects, device, synthetic(), bad).error().code, ErrorCode::kInvalidArgument);
  bad = {};
  bad.stiffness = -1.0;
  EXPECT_FALSE(HapticLoop::create(objects, device, synthetic(), bad).ok());
  bad = {};
  bad.workers = 0;
  EXPECT_FALSE(HapticLoop::create(objects, device, synthetic(), bad).ok());
  EXPECT_FALSE(HapticLoop::create(objects, device, AugmentFunction{}, {}).ok());
  const std::vector<SceneObject> empty = {{"nothing.obj", {}}};
  const auto r = HapticLoop::create(empty, device, synthetic(), {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("nothing.obj"), std::string::npos);
}

// Better data (an object's exact data, learned in the background) come after the first: an augmentation
// whose upgrade is ready once `go` is set, and then gives the box with modes twice as stiff.
AugmentFunction upgradingBox(const std::shared_ptr<std::atomic<bool>>& go,
                             std::atomic<int>* makes = nullptr) {
  return [go, makes](const SceneObject& object) -> Result<AugmentedObject> {
    auto first = test::augmentBox(object);
    if (!first) return first;
    first->upgrade = Upgrade{[go] { return go->load(); },
                             [object, makes]() -> Result<std::optional<AugmentedObject>> {
                               if (makes) ++*makes;
                               auto better = test::augmentBox(object);
                               if (!better) return better.error();
                               better->source = "learned-box";
                               better->physics.eigenvalues *= 4.0;
                               return std::optional<AugmentedObject>(std::move(better).value());
                             }};
    return first;
  };
}

TEST(HapticLoop, BetterDataAreSwappedInWhenReadyAndReported) {
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes({{0.0, Vec3(0.01, 0.02, 0.053)}});
  auto go = std::make_shared<std::atomic<bool>>(false);
  std::atomic<int> makes{0};
  auto loop = HapticLoop::create(objects, device, upgradingBox(go, &makes), LoopOptions{});
  ASSERT_TRUE(loop.ok());
  const LoopReport before = (*loop)->simulate(0.5);
  ASSERT_EQ(before.objectsAugmented, 1u);
  EXPECT_EQ(before.upgrades, 0u);
  EXPECT_EQ(before.upgradesPending, 1u);
  EXPECT_EQ((*loop)->augmentation(0)->source, "synthetic-box");
  const double firstOmega = (*loop)->augmentation(0)->physics.eigenvalues[0];

  go->store(true);
  const LoopReport after = (*loop)->simulate(0.5);
  EXPECT_EQ(makes.load(), 1);
  EXPECT_EQ(after.upgrades, 1u);
  EXPECT_EQ(after.upgradesPending, 0u);
  const ObjectOutcome& o = after.objects.front();
  EXPECT_TRUE(o.upgraded);
  EXPECT_EQ(o.source, "learned-box");
  EXPECT_EQ(o.firstSource, "synthetic-box");
  // Requested at t = 0; the upgrade found ready after the tick at t = 0.5, swapped in at the next.
  EXPECT_NEAR(o.upgradeSeconds, 0.501, 1e-9);
  EXPECT_EQ((*loop)->augmentation(0)->source, "learned-box");
  EXPECT_DOUBLE_EQ((*loop)->augmentation(0)->physics.eigenvalues[0], 4.0 * firstOmega);
  EXPECT_GT(after.contactTicks, 0u);  // the proxy still presses, now on the new modes
  EXPECT_NE((*loop)->modalCoordinates(0).norm(), 0.0);
}

TEST(HapticLoop, AnUpgradeThatFailsOrHasNothingBetterKeepsTheFirstData) {
  const std::vector<SceneObject> objects = {test::boxObject("fails", Vec3::Zero(), 0.1),
                                            test::boxObject("same", Vec3(0.3, 0.0, 0.0), 0.1)};
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes({{0.0, Vec3(0.15, 0.0, 0.0)}});
  LoopOptions options;
  options.augmentationRadius = 0.2;
  auto loop = HapticLoop::create(
      objects, device,
      [](const SceneObject& object) -> Result<AugmentedObject> {
        auto first = test::augmentBox(object);
        if (!first) return first;
        const bool fails = object.name == "fails";
        first->upgrade = Upgrade{[] { return true; },
                                 [fails]() -> Result<std::optional<AugmentedObject>> {
                                   if (fails) return Error{ErrorCode::kNotClosed, "fails.obj: not learned"};
                                   return std::optional<AugmentedObject>();
                                 }};
        return first;
      },
      options);
  ASSERT_TRUE(loop.ok());
  const LoopReport report = (*loop)->simulate(0.2);
  ASSERT_EQ(report.objectsAugmented, 2u);
  EXPECT_EQ(report.upgrades, 0u);
  EXPECT_EQ(report.upgradesPending, 0u);
  EXPECT_EQ(report.objects[0].upgradeError, "fails.obj: not learned");
  EXPECT_TRUE(report.objects[1].upgradeError.empty());
  for (const ObjectOutcome& o : report.objects) {
    EXPECT_FALSE(o.upgraded);
    EXPECT_EQ(o.source, "synthetic-box");
  }
}

// The real-time loop with its own threads: the upgrade becomes ready while the proxy presses the box, the
// upgrade thread publishes it and a tick swaps it in; readers meanwhile see one data set or the other,
// whole (the tsan preset runs this).
TEST(HapticLoop, UpgradesInRealTimeWhileReadersWatch) {
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes({{0.0, Vec3(0.01, 0.02, 0.053)}});
  auto go = std::make_shared<std::atomic<bool>>(false);
  auto loop = HapticLoop::create(objects, device, upgradingBox(go), LoopOptions{});
  ASSERT_TRUE(loop.ok());
  std::atomic<bool> done{false};
  std::atomic<int> inconsistent{0};
  std::thread reader([&] {
    while (!done.load()) {
      if (const AugmentedObject* data = (*loop)->augmentation(0)) {
        const Eigen::VectorXd q = (*loop)->modalCoordinates(0);
        if (q.size() != data->physics.eigenvalues.size()) ++inconsistent;
      }
      std::this_thread::yield();
    }
  });
  std::thread trigger([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    go->store(true);
  });
  const LoopReport report = (*loop)->run(0.5);
  trigger.join();
  done = true;
  reader.join();
  EXPECT_EQ(inconsistent.load(), 0);
  ASSERT_EQ(report.objectsAugmented, 1u);
  EXPECT_EQ(report.upgrades, 1u);
  EXPECT_TRUE(report.objects.front().upgraded);
  EXPECT_GT(report.objects.front().upgradeSeconds, 0.1);
  EXPECT_LT(report.objects.front().upgradeSeconds, 0.5);
  EXPECT_EQ((*loop)->augmentation(0)->source, "learned-box");
}

}  // namespace
}  // namespace shapedb::haptics
