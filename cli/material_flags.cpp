#include "material_flags.h"

#include "commands.h"

namespace shapedb::cli {

void addMaterialFlags(CLI::App& app, MaterialFlags& flags) {
  app.add_option("--material", flags.preset,
                 "Material preset: steel, aluminium, glass, wood, rubber, concrete")
      ->capture_default_str();
  app.add_option("--density", flags.density, "Custom material: density, kg/m³");
  app.add_option("--youngs", flags.youngs, "Custom material: Young's modulus, Pa");
  app.add_option("--poisson", flags.poisson, "Custom material: Poisson ratio (default 0.3)");
}

std::optional<core::Material> resolveMaterial(const MaterialFlags& flags, const CLI::App& app) {
  const bool custom = app.count("--density") + app.count("--youngs") + app.count("--poisson") > 0;
  if (!custom) {
    auto preset = core::materialPreset(flags.preset);
    if (!preset) {
      printError(preset.error().message);
      return std::nullopt;
    }
    return *preset;
  }
  if (app.count("--material")) {
    printError("--material and --density/--youngs/--poisson exclude each other");
    return std::nullopt;
  }
  if (!app.count("--density") || !app.count("--youngs")) {
    printError("a custom material needs --density and --youngs (--poisson defaults to 0.3)");
    return std::nullopt;
  }
  core::Material material{"custom", flags.density, flags.youngs,
                          app.count("--poisson") ? flags.poisson : 0.3};
  if (Status st = core::validateMaterial(material); !st) {
    printError(st.error().message);
    return std::nullopt;
  }
  return material;
}

}  // namespace shapedb::cli
