#pragma once
// CHOLMOD allocates through SuiteSparse's configurable allocator (SuiteSparse_config): while a
// CholmodMemoryLimit lives, every block over its limit is refused, as on a machine without the memory a
// large factor needs. One at a time, and not beside other threads that factorize (the allocator is global).

#include <cstddef>
#include <cstdlib>
#include <suitesparse/SuiteSparse_config.h>

namespace shapedb::test {

class CholmodMemoryLimit {
 public:
  explicit CholmodMemoryLimit(std::size_t bytes) : mSaved(SuiteSparse_config) {
    limit() = bytes;
    SuiteSparse_config.malloc_func = [](std::size_t size) {
      return size > limit() ? nullptr : std::malloc(size);
    };
    SuiteSparse_config.calloc_func = [](std::size_t count, std::size_t size) {
      return count * size > limit() ? nullptr : std::calloc(count, size);
    };
    SuiteSparse_config.realloc_func = [](void* p, std::size_t size) {
      return size > limit() ? nullptr : std::realloc(p, size);
    };
  }
  ~CholmodMemoryLimit() { SuiteSparse_config = mSaved; }
  CholmodMemoryLimit(const CholmodMemoryLimit&) = delete;
  CholmodMemoryLimit& operator=(const CholmodMemoryLimit&) = delete;

 private:
  static std::size_t& limit() {
    static std::size_t bytes = 0;
    return bytes;
  }
  SuiteSparse_config_struct mSaved;
};

}  // namespace shapedb::test
