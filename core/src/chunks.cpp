#include <tbb/parallel_for.h>

#include <shapedb/core/chunks.h>

namespace shapedb::core {

void Chunks::run(const std::function<void(std::size_t, std::size_t, std::size_t)>& f) const {
  if (count == 1) {
    f(std::size_t{0}, std::size_t{0}, items);
    return;
  }
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t c) { f(c, begin(c), end(c)); });
}

}  // namespace shapedb::core
