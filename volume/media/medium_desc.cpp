#include "volume/media/medium_desc.h"

#include "src/core/names.h"

namespace lvox {
namespace {

constexpr Named<MediumType> kMediumTypes[] = {{MediumType::Vdb, "vdb"},
                                              {MediumType::Homogeneous, "homogeneous"},
                                              {MediumType::Procedural, "procedural"}};
constexpr Named<ProceduralKind> kProceduralKinds[] = {
    {ProceduralKind::Constant, "constant"},
    {ProceduralKind::LinearRamp, "linear_ramp"},
    {ProceduralKind::GaussianBlob, "gaussian_blob"},
    {ProceduralKind::Noise, "noise"}};

MediumType parseMediumType(std::string_view name, const std::string& file,
                           const std::string& field) {
  return parseNamed(name, kMediumTypes, "medium type", file, field);
}

ProceduralKind parseProceduralKind(std::string_view name, const std::string& file,
                                   const std::string& field) {
  return parseNamed(name, kProceduralKinds, "procedural kind", file, field);
}

void parseVdb(JsonObject& m, MediumDesc& d) {
  d.file = m.filePath("file");
  d.grid = m.string("grid", "density");
  if (d.grid.empty()) m.fail("grid", "must not be empty");
  d.emissionGrid = m.string("emission_grid", std::string());
  d.densityScale = m.number("density_scale", 0.0f, 1e9f, 1.0f);
  d.albedo = m.rgb("albedo", 0.0f, 1.0f, RGB(0.8f));
  d.emission = m.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
  d.temperatureGrid = m.string("temperature_grid", std::string());
  // 1e5 K: sigma T^4 / pi = 1.8e12 W m^-2 sr^-1, far above any flame, well inside floats.
  d.temperature = m.number("temperature", 0.0f, 1e5f, 1000.0f);
  d.blackbodyIntensity = m.number("blackbody_intensity", 0.0f, 1e9f, 1.0f);
  d.transform = parseTransform(m, "transform");
}

void parseProcedural(JsonObject& m, MediumDesc& d) {
  d.procedural = m.choice("kind", std::nullopt, parseProceduralKind);
  switch (d.procedural) {
    case ProceduralKind::Constant:
      break;
    case ProceduralKind::LinearRamp:
      d.gradient = m.vec3("gradient");
      break;
    case ProceduralKind::GaussianBlob:
      d.center = m.vec3("center");
      d.radius = m.number("radius", 1e-6f, 1e9f, std::nullopt);
      break;
    case ProceduralKind::Noise:
      d.frequency = m.number("frequency", 1e-6f, 1e6f, std::nullopt);
      break;
  }
}

void parseBox(JsonObject& m, MediumDesc& d) {
  d.boxMin = m.vec3("min");
  d.boxMax = m.vec3("max");
  if (!(d.boxMin.x < d.boxMax.x && d.boxMin.y < d.boxMax.y && d.boxMin.z < d.boxMax.z))
    m.fail("max", "must exceed min on every axis");
  d.sigmaA = m.rgb("sigma_a", 0.0f, 1e9f, RGB(0.0f));
  d.sigmaS = m.rgb("sigma_s", 0.0f, 1e9f, RGB(0.0f));
  d.emission = m.rgb("emission", 0.0f, 1e9f, RGB(0.0f));
  if (d.type == MediumType::Procedural) parseProcedural(m, d);
}

}  // namespace

MediumDesc parseMedium(JsonObject m) {
  MediumDesc d;
  d.field = m.path();
  d.type = m.choice("type", std::nullopt, parseMediumType);
  d.g = m.number("g", -0.999f, 0.999f, 0.0f);
  d.phase = m.choice("phase", d.g == 0.0f ? "isotropic" : "hg", parsePhaseKind);
  if (d.type == MediumType::Vdb)
    parseVdb(m, d);
  else
    parseBox(m, d);
  m.finish();
  return d;
}

}  // namespace lvox
