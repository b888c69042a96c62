#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <pthread.h>
#include <semaphore>
#include <string>
#include <sys/resource.h>
#include <thread>

#include <shapedb/core/statistics.h>
#include <shapedb/haptics/contact.h>
#include <shapedb/haptics/loop.h>

namespace shapedb::haptics {

TrajectoryDevice sweepThrough(const std::vector<SceneObject>& objects, double speed) {
  core::Vec3 lo = core::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  std::vector<double> widths;
  for (const SceneObject& object : objects) {
    const core::Bounds b = core::computeBounds(object.mesh);
    lo = lo.cwiseMin(b.min);
    hi = hi.cwiseMax(b.max);
    widths.push_back((b.max - b.min).head<2>().maxCoeff());
  }
  const double width = std::max(core::median(widths), 1e-9);
  const int lanes = std::clamp(static_cast<int>(std::ceil((hi.y() - lo.y()) / width)), 1, 200);
  return TrajectoryDevice::sweep(lo, hi, lanes, speed);
}

using core::Vec3;
using State = ObjectOutcome::State;
using Clock = std::chrono::steady_clock;

namespace {

constexpr std::uint32_t kNoRequest = std::numeric_limits<std::uint32_t>::max();
/// A vibrating object stops being stepped when its energy has fallen this far below its peak (80 dB).
constexpr double kRestEnergyRatio = 1e-8;

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

Percentiles percentiles(std::vector<double> values) {
  Percentiles p;
  if (values.empty()) return p;
  p.p50 = core::percentile(values, 0.50);
  p.p99 = core::percentile(values, 0.99);
  p.max = *std::max_element(values.begin(), values.end());
  return p;
}

}  // namespace

/// Everything the loop holds. The tick thread, run()'s workers and the callers of the snapshot accessors
/// share it; the comments on each member say who writes it.
class HapticLoop::Impl {
 public:
  /// An augmented object as the tick uses it: published once by a worker, then read and stepped by the
  /// tick thread only (the snapshot excepted, which any thread may read).
  struct Live {
    AugmentedObject data;
    std::vector<ModeStep> steps;  ///< per mode, for the loop's period
    Eigen::VectorXd omegaSquared;
    Eigen::VectorXd q, v;     ///< modal coordinates and velocities
    Eigen::VectorXd force;    ///< modal forces gathered during the current tick
    double peakEnergy = 0.0;  ///< since the object last came to rest
    bool active = false;
    bool touched = false;  ///< in contact during the current tick
    Vec3 center = Vec3::Zero();
    double reach = 0.0;  ///< bounding radius of the collision compound about `center`
    core::TetLocator::Hint hint;
    // Seqlock, without fences (ThreadSanitizer does not model them): odd while the tick writes `snapshot`.
    std::atomic<std::uint32_t> sequence{0};
    std::unique_ptr<std::atomic<double>[]> snapshot;
  };

  struct Slot {
    std::atomic<State> state{State::kUntouched};
    /// The data in use: the first published by a worker; then, if better data come, the tick swaps
    /// `better` in. Both stay owned for the loop's life (other threads may hold either).
    std::atomic<Live*> live{nullptr};
    std::unique_ptr<Live> owned;  ///< set by the worker before `live` is published
    std::atomic<Live*> better{nullptr};
    std::unique_ptr<Live> ownedBetter;  ///< set by the upgrade thread before `better` is published
    double swappedAt = 0.0;             ///< tick time of the swap (the tick's)
    bool swapped = false;               ///< the tick's
    std::string upgradeError;           ///< the upgrade thread's, under mUpgradeMutex
    std::string error;                  ///< set by the worker before state becomes kFailed
    double requestedAt = 0.0;           ///< tick time of the request
    double readyAt = 0.0;               ///< set before `live` is published
    Vec3 center = Vec3::Zero();         ///< bounding sphere of the surface
    double radius = 0.0;
  };

  Impl(std::span<const SceneObject> objects, ProxyDevice& device, AugmentFunction augment,
       const LoopOptions& options);
  LoopReport run(double seconds);
  LoopReport simulate(double seconds);
  Vec3 tick(double seconds);
  const AugmentedObject* augmentation(std::size_t object) const;
  Eigen::VectorXd modalCoordinates(std::size_t object) const;
  std::vector<Vec3> deformedSurface(std::size_t object) const;

  /// Augments and publishes; `readySeconds` stamps the time (none: now, on run()'s clock).
  void serve(std::uint32_t object, std::optional<double> readySeconds);
  /// The tick's form of an object's data, or why they cannot be used.
  Result<std::unique_ptr<Live>> makeLive(std::uint32_t object, AugmentedObject data) const;
  /// Makes and publishes the better data of every object whose upgrade is ready (upgrade thread, or
  /// simulate()'s).
  void pollUpgrades();
  void workerMain();
  std::uint32_t popRequest();  ///< UINT32_MAX when none
  void respond(Slot& slot, Live& live, const core::Vec3& proxy, core::Vec3& force);
  LoopReport report(double seconds, std::size_t ticks, std::size_t misses) const;
  void resetStatistics(std::size_t expectedTicks);

  std::span<const SceneObject> mObjects;
  ProxyDevice& mDevice;
  AugmentFunction mAugment;
  LoopOptions mOptions;
  double mPeriod = 0.001;

  std::unique_ptr<Slot[]> mSlots;
  // Requests: written by the tick (one producer), read by the workers under mPopMutex. Each object is
  // requested once, so a ring of one place per object never wraps.
  std::vector<std::uint32_t> mRequests;
  std::atomic<std::uint32_t> mRequestsWritten{0};
  std::uint32_t mRequestsRead = 0;  ///< guarded by mPopMutex
  std::mutex mPopMutex;             ///< workers only: the tick never takes it
  std::counting_semaphore<> mPending{0};
  mutable std::mutex mUpgradeMutex;       ///< workers and the upgrade thread: the tick never takes it
  std::vector<std::uint32_t> mUpgrading;  ///< objects whose better data are to come
  std::atomic<bool> mStopping{false};
  double mClockOffset = 0.0;  ///< seconds of earlier runs: the loop's time goes on from one run to the next
  std::chrono::steady_clock::time_point mRunStart;  ///< run(): set before the workers start
  double mRunOffset = 0.0;

  // The tick's own state (one thread at a time).
  std::vector<std::uint32_t> mActive;  ///< objects in contact or still vibrating; capacity: all
  std::vector<float> mTickMicros;      ///< capacity reserved before the ticks
  std::vector<float> mLateMicros;      ///< run(): how late each tick started
  std::vector<core::Vec3> mForces;
  std::size_t mContactTicks = 0;
  double mMaxForce = 0.0;
};

Result<std::unique_ptr<HapticLoop>> HapticLoop::create(std::span<const SceneObject> objects,
                                                       ProxyDevice& device, AugmentFunction augment,
                                                       const LoopOptions& options) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  const auto nonNegative = [](double x) { return std::isfinite(x) && x >= 0.0; };
  if (!positive(options.rateHz) || options.rateHz > 1e6)
    return Error{ErrorCode::kInvalidArgument, "rate must be in (0, 1e6] Hz"};
  if (!nonNegative(options.augmentationRadius) || !positive(options.proxyRadius) ||
      !positive(options.stiffness) || !positive(options.maxForce) || !nonNegative(options.spinSeconds) ||
      !nonNegative(options.simulatedAugmentationSeconds))
    return Error{ErrorCode::kInvalidArgument,
                 "augmentation radius, proxy radius, stiffness, force limit and spin time must be finite "
                 "and positive (radius and spin may be 0)"};
  if (options.workers < 1) return Error{ErrorCode::kInvalidArgument, "at least one worker thread"};
  if (!augment) return Error{ErrorCode::kInvalidArgument, "no augment function"};
  if (objects.size() >= kNoRequest) return Error{ErrorCode::kInvalidArgument, "too many objects"};
  for (const SceneObject& object : objects)
    if (object.mesh.vertices.empty() || object.mesh.triangles.empty())
      return Error{ErrorCode::kEmptyMesh, object.name + ": the object has no surface"};
  return std::unique_ptr<HapticLoop>(
      new HapticLoop(std::make_unique<Impl>(objects, device, std::move(augment), options)));
}

HapticLoop::Impl::Impl(std::span<const SceneObject> objects, ProxyDevice& device, AugmentFunction augment,
                       const LoopOptions& options)
    : mObjects(objects),
      mDevice(device),
      mAugment(std::move(augment)),
      mOptions(options),
      mPeriod(1.0 / options.rateHz),
      mSlots(std::make_unique<Slot[]>(objects.size())),
      mRequests(objects.size()) {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const core::Bounds box = core::computeBounds(objects[i].mesh);
    Slot& slot = mSlots[i];
    slot.center = 0.5 * (box.min + box.max);
    for (const Vec3& p : objects[i].mesh.vertices)
      slot.radius = std::max(slot.radius, (p - slot.center).norm());
  }
  mActive.reserve(objects.size());
}

const AugmentedObject* HapticLoop::Impl::augmentation(std::size_t object) const {
  const Live* live = mSlots[object].live.load(std::memory_order_acquire);
  return live ? &live->data : nullptr;
}

Eigen::VectorXd HapticLoop::Impl::modalCoordinates(std::size_t object) const {
  const Live* live = mSlots[object].live.load(std::memory_order_acquire);
  if (!live) return {};
  Eigen::VectorXd q(live->q.size());
  for (;;) {
    const std::uint32_t before = live->sequence.load(std::memory_order_acquire);
    if (before % 2 == 0) {
      // Acquire loads: the second read of the sequence cannot move before them, and a value written after
      // the sequence turned odd brings that odd sequence with it.
      for (Eigen::Index j = 0; j < q.size(); ++j)
        q[j] = live->snapshot[j].load(std::memory_order_acquire);
      if (live->sequence.load(std::memory_order_relaxed) == before) return q;
    }
    std::this_thread::yield();
  }
}

std::vector<Vec3> HapticLoop::Impl::deformedSurface(std::size_t object) const {
  const std::vector<Vec3>& rest = mObjects[object].mesh.vertices;
  const AugmentedObject* data = augmentation(object);
  if (!data) return rest;
  const Eigen::VectorXd q = modalCoordinates(object);
  const Eigen::VectorXd u = data->physics.modeShapes * q;
  std::vector<Vec3> out;
  core::deformSurface(data->link, data->physics.tetMesh, u, rest, out);
  return out;
}

Result<std::unique_ptr<HapticLoop::Impl::Live>> HapticLoop::Impl::makeLive(std::uint32_t object,
                                                                           AugmentedObject data) const {
  const Slot& slot = mSlots[object];
  const SceneObject& scene = mObjects[object];
  auto live = std::make_unique<Live>();
  live->data = std::move(data);
  const core::AdaptedPhysics& physics = live->data.physics;
  const auto modes = physics.eigenvalues.size();
  const auto rows = static_cast<Eigen::Index>(3 * physics.tetMesh.nodeCount());
  if (physics.modeShapes.rows() != rows || physics.modeShapes.cols() != modes || !live->data.locator ||
      live->data.locator->tetCount() != physics.tetMesh.tetCount() || physics.collision.shapes.empty() ||
      live->data.link.locations.size() != scene.mesh.vertices.size())
    return Error{ErrorCode::kInvalidArgument,
                 scene.name + ": augmentation gave inconsistent data (modes, locator, collision or link)"};
  if (!(physics.eigenvalues.array() > 0.0).all())
    return Error{ErrorCode::kInvalidArgument, scene.name + ": augmentation gave a non-positive eigenvalue"};

  const Eigen::VectorXd zeta = physics.dampingRatios();
  live->omegaSquared = physics.eigenvalues;
  for (Eigen::Index j = 0; j < modes; ++j)
    live->steps.push_back(exactModeStep(std::sqrt(physics.eigenvalues[j]), zeta[j], mPeriod));
  live->q = Eigen::VectorXd::Zero(modes);
  live->v = Eigen::VectorXd::Zero(modes);
  live->force = Eigen::VectorXd::Zero(modes);
  live->snapshot = std::make_unique<std::atomic<double>[]>(static_cast<std::size_t>(modes));
  for (Eigen::Index j = 0; j < modes; ++j)
    live->snapshot[j].store(0.0, std::memory_order_relaxed);
  live->center = slot.center;
  live->reach = std::max(slot.radius, boundingRadius(physics.collision.shapes, slot.center));
  return live;
}

void HapticLoop::Impl::serve(std::uint32_t object, std::optional<double> readySeconds) {
  Slot& slot = mSlots[object];
  const auto fail = [&](std::string message) {
    slot.error = std::move(message);
    slot.state.store(State::kFailed, std::memory_order_release);
  };
  Result<AugmentedObject> result = Error{ErrorCode::kInvalidArgument, ""};
  try {
    result = mAugment(mObjects[object]);
  } catch (const std::exception& e) {
    return fail(std::string("augmentation threw: ") + e.what());
  }
  if (!result) return fail(result.error().message);
  auto live = makeLive(object, std::move(result).value());
  if (!live) return fail(live.error().message);

  slot.readyAt = readySeconds ? *readySeconds : mRunOffset + secondsBetween(mRunStart, Clock::now());
  const bool upgrade = (*live)->data.upgrade.has_value();
  Live* published = live->get();
  slot.owned = std::move(live).value();
  slot.live.store(published, std::memory_order_release);
  slot.state.store(State::kReady, std::memory_order_release);
  if (upgrade) {
    std::lock_guard lock(mUpgradeMutex);
    mUpgrading.push_back(object);
  }
}

void HapticLoop::Impl::pollUpgrades() {
  std::lock_guard lock(mUpgradeMutex);
  for (std::size_t i = 0; i < mUpgrading.size();) {
    const std::uint32_t object = mUpgrading[i];
    Slot& slot = mSlots[object];
    const Upgrade& upgrade = *slot.owned->data.upgrade;
    if (!upgrade.ready()) {
      ++i;
      continue;
    }
    mUpgrading[i] = mUpgrading.back();
    mUpgrading.pop_back();
    Result<std::optional<AugmentedObject>> better = Error{ErrorCode::kInvalidArgument, ""};
    try {
      better = upgrade.make();
    } catch (const std::exception& e) {
      better = Error{ErrorCode::kInvalidArgument, std::string("the upgrade threw: ") + e.what()};
    }
    if (!better) {
      slot.upgradeError = better.error().message;
      continue;
    }
    if (!better->has_value()) continue;  // the first data were the best
    AugmentedObject data = std::move(**better);
    data.upgrade.reset();  // one upgrade an object
    auto live = makeLive(object, std::move(data));
    if (!live) {
      slot.upgradeError = live.error().message;
      continue;
    }
    Live* published = live->get();
    slot.ownedBetter = std::move(live).value();
    slot.better.store(published, std::memory_order_release);
  }
}

std::uint32_t HapticLoop::Impl::popRequest() {
  std::lock_guard lock(mPopMutex);
  if (mRequestsRead == mRequestsWritten.load(std::memory_order_acquire)) return kNoRequest;
  return mRequests[mRequestsRead++];
}

void HapticLoop::Impl::respond(Slot& slot, Live& live, const Vec3& proxy, Vec3& force) {
  const AugmentedObject& data = live.data;
  const SurfaceDistance contact = signedDistance(data.physics.collision.shapes, proxy);
  if (contact.distance >= mOptions.proxyRadius) return;

  // The contact point on the object, in its tets; the surface there has moved by u = Σ wᵢ Φ(nodeᵢ) q.
  const core::TetLocation where = data.locator->locate(data.locatorFrame.toEntry(contact.point), live.hint);
  const core::TetMesh::Tet& tet = data.physics.tetMesh.tets[where.tet];
  const Eigen::MatrixXd& phi = data.physics.modeShapes;
  const Eigen::Index modes = phi.cols();
  Vec3 moved = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(tet[k]);
    for (Eigen::Index j = 0; j < modes; ++j)
      for (int a = 0; a < 3; ++a)
        moved[a] += where.weights[k] * phi(row + a, j) * live.q[j];
  }
  const double depth = mOptions.proxyRadius - contact.distance + contact.normal.dot(moved);
  if (depth <= 0.0) return;
  const double magnitude = std::min(mOptions.stiffness * depth, mOptions.maxForce);
  const Vec3 onProxy = magnitude * contact.normal;
  force += onProxy;

  // The reaction, −onProxy at the contact point, spread over the tet's nodes: modal force φⱼᵀ f.
  for (int k = 0; k < 4; ++k) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(tet[k]);
    for (Eigen::Index j = 0; j < modes; ++j)
      for (int a = 0; a < 3; ++a)
        live.force[j] -= where.weights[k] * phi(row + a, j) * onProxy[a];
  }
  live.touched = true;
  if (!live.active) {
    live.active = true;
    mActive.push_back(static_cast<std::uint32_t>(&slot - mSlots.get()));  // capacity: every object
  }
}

Vec3 HapticLoop::Impl::tick(double seconds) {
  const Vec3 proxy = mDevice.position(seconds);
  Vec3 force = Vec3::Zero();

  for (std::size_t i = 0; i < mObjects.size(); ++i) {
    Slot& slot = mSlots[i];
    const double distance = (proxy - slot.center).norm();
    if (Live* live = slot.live.load(std::memory_order_acquire)) {
      if (!slot.swapped) {
        if (Live* better = slot.better.load(std::memory_order_acquire)) {
          // Better data: in use from this tick on, from rest. The old data stay owned, so readers that
          // hold them are safe; an object still vibrating stays in mActive and goes on with the new.
          better->active = live->active;
          slot.live.store(better, std::memory_order_release);
          slot.swapped = true;
          slot.swappedAt = seconds;
          live = better;
        }
      }
      if (distance < live->reach + mOptions.proxyRadius) respond(slot, *live, proxy, force);
      continue;
    }
    if (!mOptions.requestAllAtStart && distance > slot.radius + mOptions.augmentationRadius) continue;
    if (slot.state.load(std::memory_order_relaxed) != State::kUntouched) continue;
    // Post it: the workers pop in order; the semaphore wakes one (a futex, no lock).
    slot.requestedAt = seconds;
    slot.state.store(State::kPending, std::memory_order_relaxed);
    const std::uint32_t written = mRequestsWritten.load(std::memory_order_relaxed);
    mRequests[written] = static_cast<std::uint32_t>(i);
    mRequestsWritten.store(written + 1, std::memory_order_release);
    mPending.release();
  }

  const double norm = force.norm();
  if (norm > mOptions.maxForce) force *= mOptions.maxForce / norm;  // several contacts at once

  // Modal dynamics of every object in contact or still vibrating: one exact step each.
  for (std::size_t a = 0; a < mActive.size();) {
    Live& live = *mSlots[mActive[a]].live.load(std::memory_order_relaxed);  // the tick's own store
    double energy = 0.0;
    const Eigen::Index modes = live.q.size();
    const std::uint32_t sequence = live.sequence.load(std::memory_order_relaxed);
    live.sequence.store(sequence + 1, std::memory_order_relaxed);  // odd: the snapshot is being written
    for (Eigen::Index j = 0; j < modes; ++j) {
      live.steps[static_cast<std::size_t>(j)].advance(live.q[j], live.v[j], live.force[j]);
      live.force[j] = 0.0;
      energy += 0.5 * (live.v[j] * live.v[j] + live.omegaSquared[j] * live.q[j] * live.q[j]);
    }
    live.peakEnergy = std::max(live.peakEnergy, energy);
    const bool rest = !live.touched && energy <= kRestEnergyRatio * live.peakEnergy;
    if (rest) {
      live.q.setZero();
      live.v.setZero();
      live.peakEnergy = 0.0;
    }
    // Release stores (plain moves on x86): a reader that sees one of these values sees the odd sequence.
    for (Eigen::Index j = 0; j < modes; ++j)
      live.snapshot[j].store(live.q[j], std::memory_order_release);
    live.sequence.store(sequence + 2, std::memory_order_release);
    live.touched = false;
    if (rest) {
      live.active = false;
      mActive[a] = mActive.back();
      mActive.pop_back();
    } else {
      ++a;
    }
  }

  mDevice.applyForce(seconds, force);
  if (norm > 0.0) {
    ++mContactTicks;
    mMaxForce = std::max(mMaxForce, force.norm());
  }
  if (mOptions.recordForces && mForces.size() < mForces.capacity()) mForces.push_back(force);
  return force;
}

void HapticLoop::Impl::resetStatistics(std::size_t expectedTicks) {
  // Filled once and cleared: the pages are touched now, so that the ticks do not fault them in.
  mTickMicros.assign(expectedTicks, 0.0f);
  mTickMicros.clear();
  mLateMicros.assign(expectedTicks, 0.0f);
  mLateMicros.clear();
  mForces.clear();
  if (mOptions.recordForces) {
    mForces.assign(expectedTicks, Vec3::Zero());
    mForces.clear();
  }
  mContactTicks = 0;
  mMaxForce = 0.0;
}

void HapticLoop::Impl::workerMain() {
  for (;;) {
    mPending.acquire();
    if (mStopping.load(std::memory_order_acquire)) return;
    const std::uint32_t object = popRequest();
    if (object == kNoRequest) continue;
    serve(object, std::nullopt);
  }
}

LoopReport HapticLoop::Impl::run(double seconds) {
  const auto ticks = static_cast<std::size_t>(std::ceil(seconds * mOptions.rateHz));
  resetStatistics(ticks + 1);
  const double offset = mClockOffset;
  const Clock::time_point start = Clock::now();
  mRunStart = start;  // the workers stamp the time their data are ready on the loop's clock
  mRunOffset = offset;
  mStopping.store(false, std::memory_order_release);
  std::vector<std::thread> workers;
  for (int w = 0; w < mOptions.workers; ++w)
    workers.emplace_back([this] { workerMain(); });
  // Better data are waited for on a thread of their own: an upgrade may take seconds to be ready, and
  // must not hold up the first data of other objects.
  std::thread upgrader([this] {
    while (!mStopping.load(std::memory_order_acquire)) {
      pollUpgrades();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });

  std::size_t misses = 0, done = 0;
  bool realtime = false;
  std::size_t pageFaults = 0;
  std::thread loop([&] {
    // Real-time scheduling where the system grants it (root, or CAP_SYS_NICE); else the default.
    sched_param priority{};
    priority.sched_priority = 10;
    realtime = pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority) == 0;
    rusage before{};
    getrusage(RUSAGE_THREAD, &before);
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(mPeriod));
    const auto spin =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(mOptions.spinSeconds));
    Clock::time_point next = start;
    for (std::size_t k = 0; k < ticks; ++k) {
      if (Clock::now() < next - spin) std::this_thread::sleep_until(next - spin);
      while (Clock::now() < next) {
      }
      const Clock::time_point begin = Clock::now();
      tick(offset + secondsBetween(start, next));
      const Clock::time_point end = Clock::now();
      if (mTickMicros.size() < mTickMicros.capacity()) {
        mTickMicros.push_back(static_cast<float>(1e6 * secondsBetween(begin, end)));
        mLateMicros.push_back(static_cast<float>(1e6 * secondsBetween(next, begin)));
      }
      ++done;
      next += period;
      if (end > next) ++misses;  // finished after its own period ended
      if (end > next + period) {
        // More than a whole period behind: the ticks that cannot be made up are dropped, and missed.
        const auto behind = static_cast<std::size_t>((end - next) / period);
        next += static_cast<Clock::duration::rep>(behind) * period;
        misses += behind;
        k += behind;
      }
    }
    rusage after{};
    getrusage(RUSAGE_THREAD, &after);
    pageFaults =
        static_cast<std::size_t>((after.ru_minflt - before.ru_minflt) + (after.ru_majflt - before.ru_majflt));
  });
  loop.join();
  mStopping.store(true, std::memory_order_release);
  mPending.release(static_cast<std::ptrdiff_t>(workers.size()));
  for (std::thread& worker : workers)
    worker.join();
  upgrader.join();
  mClockOffset = offset + seconds;
  LoopReport result = report(seconds, done, misses);
  result.realtimePriority = realtime;
  result.pageFaults = pageFaults;
  return result;
}

LoopReport HapticLoop::Impl::simulate(double seconds) {
  const auto ticks = static_cast<std::size_t>(std::ceil(seconds * mOptions.rateHz));
  resetStatistics(ticks);
  const double offset = mClockOffset;
  for (std::size_t k = 0; k < ticks; ++k) {
    const double now = offset + static_cast<double>(k) * mPeriod;
    // Serve, in order, the requests whose simulated augmentation time is over.
    for (;;) {
      const std::uint32_t written = mRequestsWritten.load(std::memory_order_acquire);
      if (mRequestsRead == written) break;
      const std::uint32_t object = mRequests[mRequestsRead];
      const double ready = mSlots[object].requestedAt + mOptions.simulatedAugmentationSeconds;
      if (ready > now) break;
      ++mRequestsRead;
      serve(object, ready);
    }
    const Clock::time_point begin = Clock::now();
    tick(now);
    mTickMicros.push_back(static_cast<float>(1e6 * secondsBetween(begin, Clock::now())));
    pollUpgrades();  // after the tick, as the upgrade thread publishes between ticks: the next one swaps
  }
  mClockOffset = offset + static_cast<double>(ticks) * mPeriod;
  return report(static_cast<double>(ticks) * mPeriod, ticks, 0);
}

LoopReport HapticLoop::Impl::report(double seconds, std::size_t ticks, std::size_t misses) const {
  LoopReport r;
  r.seconds = seconds;
  r.ticks = ticks;
  r.achievedRateHz = seconds > 0.0 ? static_cast<double>(ticks) / seconds : 0.0;
  r.tickMicros = percentiles(std::vector<double>(mTickMicros.begin(), mTickMicros.end()));
  r.startLateMicros = percentiles(std::vector<double>(mLateMicros.begin(), mLateMicros.end()));
  r.deadlineMisses = misses;
  r.contactTicks = mContactTicks;
  r.maxForce = mMaxForce;
  r.forces = mForces;
  std::vector<double> latencies, upgradeLatencies;
  std::lock_guard lock(mUpgradeMutex);  // for the upgrades' errors and the pending ones
  r.upgradesPending = mUpgrading.size();
  for (std::size_t i = 0; i < mObjects.size(); ++i) {
    const Slot& slot = mSlots[i];
    ObjectOutcome outcome;
    outcome.name = mObjects[i].name;
    outcome.state = slot.state.load(std::memory_order_acquire);
    if (outcome.state == State::kReady) {
      outcome.source = slot.live.load(std::memory_order_acquire)->data.source;
      outcome.augmentationSeconds = slot.readyAt - slot.requestedAt;
      latencies.push_back(1e3 * outcome.augmentationSeconds);
      ++r.objectsAugmented;
      if (slot.swapped) {
        outcome.upgraded = true;
        outcome.firstSource = slot.owned->data.source;
        outcome.upgradeSeconds = slot.swappedAt - slot.requestedAt;
        upgradeLatencies.push_back(1e3 * outcome.upgradeSeconds);
      }
      outcome.upgradeError = slot.upgradeError;
    } else if (outcome.state == State::kFailed) {
      outcome.error = slot.error;
      ++r.objectsFailed;
    } else if (outcome.state == State::kPending) {
      ++r.objectsPending;
    }
    r.objects.push_back(std::move(outcome));
  }
  r.augmentationMillis = percentiles(std::move(latencies));
  r.upgrades = upgradeLatencies.size();
  r.upgradeMillis = percentiles(std::move(upgradeLatencies));
  return r;
}

HapticLoop::HapticLoop(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
HapticLoop::~HapticLoop() = default;

LoopReport HapticLoop::run(double seconds) {
  return mImpl->run(seconds);
}
LoopReport HapticLoop::simulate(double seconds) {
  return mImpl->simulate(seconds);
}
Vec3 HapticLoop::tick(double seconds) {
  return mImpl->tick(seconds);
}
std::size_t HapticLoop::objectCount() const {
  return mImpl->mObjects.size();
}
const AugmentedObject* HapticLoop::augmentation(std::size_t object) const {
  return mImpl->augmentation(object);
}
Eigen::VectorXd HapticLoop::modalCoordinates(std::size_t object) const {
  return mImpl->modalCoordinates(object);
}
std::vector<Vec3> HapticLoop::deformedSurface(std::size_t object) const {
  return mImpl->deformedSurface(object);
}

}  // namespace shapedb::haptics
