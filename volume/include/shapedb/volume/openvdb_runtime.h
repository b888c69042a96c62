#pragma once

#include <string>

namespace shapedb::volume {

/// Registers OpenVDB's grid types once per process. Every volume function that touches OpenVDB calls
/// it; callers never need to. Thread-safe and idempotent.
void initializeOpenVdb();

/// The OpenVDB library version this build links, "major.minor.patch".
std::string openVdbVersion();

}  // namespace shapedb::volume
