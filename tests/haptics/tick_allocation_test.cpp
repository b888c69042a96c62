// A tick allocates nothing and takes no lock. This executable replaces the global operator new and
// interposes pthread_mutex_lock to count both on the calling thread; it is built without sanitizers only
// (they replace the same functions).

#include <cstdlib>
#include <dlfcn.h>
#include <mutex>
#include <new>
#include <pthread.h>

#include <gtest/gtest.h>

#include <shapedb/haptics/loop.h>

#include "synthetic_scene.h"

namespace {
thread_local bool tCounting = false;
thread_local std::size_t tAllocations = 0;
thread_local std::size_t tLocks = 0;
}  // namespace

// Not inlined: GCC would then pair a malloc inlined from one with a free inlined from another and warn
// (-Wmismatched-new-delete) about what is, through these replacements, a matched pair.
[[gnu::noinline]] void* operator new(std::size_t size) {
  if (tCounting) ++tAllocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void* operator new(std::size_t size, std::align_val_t align) {
  if (tCounting) ++tAllocations;
  const auto a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return operator new(size, align);
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

extern "C" int pthread_mutex_lock(pthread_mutex_t* mutex) {
  using Lock = int (*)(pthread_mutex_t*);
  static const Lock next = reinterpret_cast<Lock>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  if (tCounting) ++tLocks;
  return next(mutex);
}

namespace shapedb::haptics {
namespace {

using core::Vec3;

struct Counts {
  std::size_t allocations = 0, locks = 0;
};

template <typename F>
Counts count(F&& f) {
  const std::size_t a = tAllocations, l = tLocks;
  tCounting = true;
  f();
  tCounting = false;
  return {tAllocations - a, tLocks - l};
}

TEST(TickAllocation, TheCountersSeeAnAllocationAndALock) {
  std::mutex m;
  const Counts c = count([&] {
    std::lock_guard lock(m);
    auto* v = new std::vector<int>(100);
    delete v;
  });
  EXPECT_EQ(c.allocations, 2u);  // the vector and its buffer
  EXPECT_EQ(c.locks, 1u);
}

TEST(TickAllocation, TicksAllocateNothingAndTakeNoLock) {
  // Box 0 is pressed and vibrating; box 1 comes within the augmentation radius during the counted ticks,
  // so they post a request too.
  const std::vector<SceneObject> objects = {test::boxObject("near", Vec3::Zero(), 0.1),
                                            test::boxObject("far", Vec3(0.6, 0.0, 0.0), 0.1)};
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes(
      {{0.0, Vec3(0, 0, 0.053)}, {0.5, Vec3(0, 0, 0.053)}, {1.0, Vec3(0.5, 0, 0.053)}});
  LoopOptions options;
  options.recordForces = true;  // its buffer is reserved before the ticks, not during them
  auto loop = HapticLoop::create(
      objects, device, [](const SceneObject& o) { return test::augmentBox(o); }, options);
  ASSERT_TRUE(loop.ok());
  const LoopReport warm = (*loop)->simulate(0.5);  // box 0 augmented and in contact
  ASSERT_EQ(warm.objectsAugmented, 1u);
  ASSERT_GT(warm.contactTicks, 0u);

  Vec3 total = Vec3::Zero();
  const Counts c = count([&] {
    for (int k = 0; k < 500; ++k)
      total += (*loop)->tick(0.5 + k * 1e-3);
  });
  EXPECT_EQ(c.allocations, 0u);
  EXPECT_EQ(c.locks, 0u);
  EXPECT_GT(total.z(), 0.0);                            // contact during the counted ticks
  EXPECT_NE((*loop)->modalCoordinates(0).norm(), 0.0);  // and vibration
  // And the request they posted (box 1 came in reach at t ≈ 0.96): simulate() serves it. Direct ticks
  // do not move the loop's clock, so the simulation starts again from t = 0.5.
  const LoopReport after = (*loop)->simulate(0.6);
  EXPECT_EQ(after.objectsAugmented, 2u);
}

TEST(TickAllocation, SwappingInBetterDataAllocatesNothingAndTakesNoLock) {
  // The box is pressed and vibrating; its better data are made (by simulate(), as the upgrade thread
  // would) before the counted ticks, and the first of them swaps them in.
  const std::vector<SceneObject> objects = {test::boxObject("box", Vec3::Zero(), 0.1)};
  TrajectoryDevice device = *TrajectoryDevice::fromKeyframes({{0.0, Vec3(0, 0, 0.053)}});
  bool ready = false;
  auto loop = HapticLoop::create(
      objects, device,
      [&ready](const SceneObject& o) -> Result<AugmentedObject> {
        auto first = test::augmentBox(o);
        if (!first) return first;
        first->upgrade = Upgrade{[&ready] { return ready; },
                                 [o]() -> Result<std::optional<AugmentedObject>> {
                                   auto better = test::augmentBox(o, 8);
                                   if (!better) return better.error();
                                   better->source = "better";
                                   return std::optional<AugmentedObject>(std::move(better).value());
                                 }};
        return first;
      },
      LoopOptions{});
  ASSERT_TRUE(loop.ok());
  ASSERT_EQ((*loop)->simulate(0.5).objectsAugmented, 1u);
  ready = true;
  // One simulated tick, after which simulate() polls the upgrade and publishes the better data: the next
  // tick, counted, swaps them in.
  (*loop)->simulate(0.001);
  ASSERT_EQ((*loop)->augmentation(0)->source, "synthetic-box");
  Vec3 total = Vec3::Zero();
  const Counts c = count([&] {
    for (int k = 0; k < 100; ++k)
      total += (*loop)->tick(0.5 + k * 1e-3);
  });
  EXPECT_EQ(c.allocations, 0u);
  EXPECT_EQ(c.locks, 0u);
  EXPECT_EQ((*loop)->augmentation(0)->source, "better");
  EXPECT_GT(total.z(), 0.0);
}

}  // namespace
}  // namespace shapedb::haptics
