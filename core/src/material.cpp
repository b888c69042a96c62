#include <array>
#include <cctype>
#include <cmath>
#include <string>

#include <shapedb/core/material.h>

namespace shapedb::core {

namespace {

const std::array<Material, 6> kPresets{{
    {"steel", 7850.0, 200e9, 0.30},
    {"aluminium", 2700.0, 69e9, 0.33},
    {"glass", 2500.0, 70e9, 0.22},
    {"wood", 700.0, 11e9, 0.35},
    {"rubber", 1100.0, 0.05e9, 0.49},
    {"concrete", 2400.0, 30e9, 0.20},
}};

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

Material unitMaterial(double poissonRatio) {
  return {"unit", 1.0, 1.0, poissonRatio};
}

bool validPoissonRatio(double nu) {
  return nu > -1.0 && nu < 0.5;
}

std::span<const Material> materialPresets() {
  return kPresets;
}

Result<Material> materialPreset(std::string_view name) {
  std::string key = lower(name);
  if (key == "aluminum") key = "aluminium";
  for (const Material& m : kPresets)
    if (m.name == key) return m;
  std::string names;
  for (const Material& m : kPresets)
    names += (names.empty() ? "" : ", ") + m.name;
  return Error{ErrorCode::kInvalidArgument,
               "unknown material '" + std::string(name) + "' (presets: " + names + ")"};
}

Status validateMaterial(const Material& m) {
  if (!(std::isfinite(m.density) && m.density > 0.0))
    return Error{ErrorCode::kInvalidArgument, "density must be finite and > 0 kg/m³"};
  if (!(std::isfinite(m.youngsModulus) && m.youngsModulus > 0.0))
    return Error{ErrorCode::kInvalidArgument, "Young's modulus must be finite and > 0 Pa"};
  if (!validPoissonRatio(m.poissonRatio))
    return Error{ErrorCode::kInvalidArgument,
                 "Poisson ratio must lie in (-1, 0.5), not " + std::to_string(m.poissonRatio)};
  return Ok{};
}

}  // namespace shapedb::core
