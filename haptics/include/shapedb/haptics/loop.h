#pragma once

// The haptic-rate loop (docs/architecture.md, "The haptic loop"). A dedicated thread ticks at a fixed rate
// against a steady clock. Each tick reads the proxy, posts the objects that came within the augmentation
// radius to worker threads (query, fetch, adapt, link: whatever the AugmentFunction does), and picks up the
// ones the workers have published, through one atomic pointer per object. Augmented objects in contact
// with the proxy respond through their modes and push back on it. A tick never waits for a worker, and
// never allocates, locks, logs or throws.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/adapt.h>
#include <shapedb/core/link.h>
#include <shapedb/core/result.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/haptics/device.h>
#include <shapedb/haptics/modal_step.h>

namespace shapedb::haptics {

/// An object of the scene: a surface mesh in the world frame (metres), nothing more.
struct SceneObject {
  std::string name;
  core::TriangleMesh mesh;
};

/// The default proxy path over a scene: TrajectoryDevice::sweep through the objects' bounding box at mid
/// height, one lane per typical object width (the median of their widths across x and y; at most 200
/// lanes), at `speed` m/s. Precondition: at least one object with a vertex, speed > 0.
TrajectoryDevice sweepThrough(const std::vector<SceneObject>& objects, double speed);

struct AugmentedObject;

/// Better data to come for an object already augmented: its exact data, say, being computed in the
/// background (io/enrich.h). The loop's upgrade thread polls `ready` every few milliseconds; once it holds,
/// it calls `make` once, and data that call gives replace the object's between two ticks.
struct Upgrade {
  std::function<bool()> ready;  ///< cheap, non-blocking
  /// The better data (same object, world frame), or nullopt if there are none after all (the first
  /// answer was already the best); an error keeps the first data and is reported.
  std::function<Result<std::optional<AugmentedObject>>()> make;
};

/// What augmentation gives an object: physical data that fit its surface, in the world frame.
struct AugmentedObject {
  std::string source;            ///< where the data came from (a database entry's name)
  core::AdaptedPhysics physics;  ///< tets, modes (M-orthonormal), collision compound, damping
  core::SurfaceLink link;        ///< the object's surface vertices in physics.tetMesh
  /// Locates contact points in the tets. It may be built on another copy of the same tets (a database
  /// entry's canonical ones, shared by every object that matched it): `locatorFrame` carries the
  /// locator's frame to the world, and its tets are numbered as physics.tetMesh's.
  std::shared_ptr<const core::TetLocator> locator;
  core::Placement locatorFrame;
  /// Better data to come, if any (run() and simulate() wait for them; see Upgrade). The swap costs the
  /// tick two pointer loads and no allocation; the object then starts again from rest on its new modes.
  std::optional<Upgrade> upgrade;
};

/// Runs on a worker thread: may take milliseconds, allocate, read files. An error leaves the object
/// without physical data (reported, never retried).
using AugmentFunction = std::function<Result<AugmentedObject>(const SceneObject&)>;

struct LoopOptions {
  double rateHz = 1000.0;
  /// An object is augmented when the proxy comes this close to its bounding sphere (metres).
  double augmentationRadius = 0.05;
  double proxyRadius = 0.005;  ///< the proxy is a sphere (metres)
  double stiffness = 2000.0;   ///< contact penalty, N/m
  double maxForce = 10.0;      ///< the device's limit, N
  int workers = 1;             ///< augmentation threads (run() only); upgrades have one thread of their own
  /// run(): sleep until this close to a tick's start, then spin on the clock.
  double spinSeconds = 200e-6;
  /// simulate(): the simulated time from an object's request to its data being ready.
  double simulatedAugmentationSeconds = 0.02;
  /// Keep the force of every tick in LoopReport::forces.
  bool recordForces = false;
  /// A fracture event: every object is requested at the first tick, wherever the proxy is (the
  /// augmentation radius is not used), as a fracture's fragments all need data at once. The report's
  /// augmentationMillis.max is then the burst's time to all augmented.
  bool requestAllAtStart = false;
};

struct Percentiles {
  double p50 = 0.0, p99 = 0.0, max = 0.0;
};

struct ObjectOutcome {
  std::string name;
  enum class State : std::uint8_t { kUntouched, kPending, kReady, kFailed } state = State::kUntouched;
  std::string source;                ///< kReady: where the data came from
  std::string error;                 ///< kFailed: why
  double augmentationSeconds = 0.0;  ///< kReady: entering the radius → data published
  /// Better data swapped in (AugmentedObject::upgrade): `source` is then theirs, and `firstSource` the
  /// first data's.
  bool upgraded = false;
  std::string firstSource;
  double upgradeSeconds = 0.0;  ///< upgraded: entering the radius → better data in use
  std::string upgradeError;     ///< the upgrade's error, if it gave one (the first data stay)
};

struct LoopReport {
  double seconds = 0.0;  ///< of the run (wall clock, or simulated)
  std::size_t ticks = 0;
  double achievedRateHz = 0.0;
  Percentiles tickMicros;           ///< compute time of a tick (wall clock, also in simulate())
  Percentiles startLateMicros;      ///< run(): how late a tick started after its scheduled time
  std::size_t deadlineMisses = 0;   ///< ticks that ended after their period did (run() only)
  bool realtimePriority = false;    ///< run(): the loop thread got SCHED_FIFO
  std::size_t pageFaults = 0;       ///< run(): page faults of the loop thread (each can stall it)
  Percentiles augmentationMillis;   ///< entering the radius → data ready, over the objects augmented
  std::size_t upgrades = 0;         ///< objects whose better data were swapped in (so far, over all runs)
  Percentiles upgradeMillis;        ///< entering the radius → better data in use, over those objects
  std::size_t upgradesPending = 0;  ///< objects whose better data are still to come
  std::size_t objectsAugmented = 0, objectsFailed = 0, objectsPending = 0;
  std::size_t contactTicks = 0;  ///< ticks with a force on the proxy
  double maxForce = 0.0;         ///< N
  std::vector<ObjectOutcome> objects;
  std::vector<core::Vec3> forces;  ///< per tick, with LoopOptions::recordForces
};

/// One loop over a scene. The objects and the device must outlive it. Not copyable or movable.
class HapticLoop {
 public:
  /// Errors: kInvalidArgument for options out of range or an empty object mesh.
  static Result<std::unique_ptr<HapticLoop>> create(std::span<const SceneObject> objects, ProxyDevice& device,
                                                    AugmentFunction augment, const LoopOptions& options);
  ~HapticLoop();
  HapticLoop(const HapticLoop&) = delete;
  HapticLoop& operator=(const HapticLoop&) = delete;

  /// Ticks in real time on a dedicated thread for `seconds`, with options.workers augmenting beside it;
  /// blocks until done. Objects augmented stay so for the next run.
  LoopReport run(double seconds);

  /// The same loop on a simulated clock, in the calling thread: tick k at k / rateHz, and a request made
  /// at time t is served (in this thread) at the first tick after t + simulatedAugmentationSeconds.
  /// Upgrades are polled after every tick, in this thread too (the next tick swaps them in).
  /// Deterministic: the same inputs give the same forces, to the bit.
  LoopReport simulate(double seconds);

  /// One tick at `seconds`, for a caller that runs its own clock (run() and simulate() keep theirs: it
  /// does not move). Allocation- and lock-free. The requests it posts are served by run()'s workers or
  /// by simulate(); until then they wait. Returns the force sent to the device.
  core::Vec3 tick(double seconds);

  std::size_t objectCount() const;
  /// The object's physical data once augmented, else null. Any thread.
  const AugmentedObject* augmentation(std::size_t object) const;
  /// The object's modal coordinates as the last tick left them (a consistent snapshot, any thread);
  /// empty before augmentation.
  Eigen::VectorXd modalCoordinates(std::size_t object) const;
  /// The object's surface displaced by its current modal coordinates (through the linking weights);
  /// its rest surface before augmentation.
  std::vector<core::Vec3> deformedSurface(std::size_t object) const;

 private:
  class Impl;  // the tick's state, the request ring, the workers' lock and semaphore: loop.cpp
  explicit HapticLoop(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> mImpl;
};

}  // namespace shapedb::haptics
