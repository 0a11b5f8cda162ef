#include "volume/media/media_set.h"

#include <algorithm>

#include "src/core/error.h"
#include "src/core/spherical_harmonics.h"
#include "volume/media/vdb_loader.h"

namespace lvox {
namespace {

Medium boxMedium(const MediumDesc& d) {
  Medium m;
  m.type = d.type;
  m.procedural = d.procedural;
  m.bounds.lo = d.boxMin;
  m.bounds.hi = d.boxMax;
  m.sigmaA = d.sigmaA;
  m.sigmaS = d.sigmaS;
  m.emission = d.emission;
  m.gradient = d.gradient;
  m.center = d.center;
  m.radius = d.radius;
  m.frequency = d.frequency;
  return m;
}

// Grids of the file that this medium does not read, named with what they could mean:
// Blender's caches hold density, flame, heat/temperature, velocity and more in one file.
void warnUnusedGrids(const MediumDesc& d, std::vector<std::string>& warnings) {
  std::string unused;
  for (const auto& [name, type] : listVdbGrids(d.file)) {
    if (name == d.grid || name == d.emissionGrid || name == d.temperatureGrid) continue;
    std::string meaning = "not used";
    if (type != "float")
      meaning = "not used: " + type + " grids (velocity, colour) have no meaning for a medium";
    else if (name == "flame" || name == "fire")
      meaning = "not used; as \"emission_grid\" it scales the emission";
    else if (name == "temperature" || name == "heat")
      meaning = "not used; as \"temperature_grid\" it gives blackbody emission";
    unused += (unused.empty() ? "" : ", ") + ("'" + name + "' (" + meaning + ")");
  }
  if (!unused.empty()) warnings.push_back(d.file + ": grids " + unused);
}

}  // namespace

MediaSet MediaSet::build(const std::vector<MediumDesc>& media, Interpolation interpolation,
                         std::vector<std::string>& warnings, MemoryBudget* budget) {
  MediaSet set;
  for (const MediumDesc& d : media) {
    Medium m;
    if (d.type == MediumType::Vdb) {
      // Each grid's tree, reserved before OpenVDB reads it.
      auto reserve = [&](const std::string& field, const std::string& grid) {
        return [=](uint64_t bytes) {
          if (budget)
            budget->reserve(bytes, d.file, field, "grid '" + grid + "' as OpenVDB holds it");
        };
      };
      GridLoadReport report;
      auto grid =
          std::make_shared<SparseGrid>(loadVdbGrid(d.file, d.grid, d.transform, d.field + ".grid",
                                                   report, reserve(d.field + ".grid", d.grid)));
      if (report.clampedNegative > 0)
        warnings.push_back(d.file + ": " + std::to_string(report.clampedNegative) +
                           " negative voxels clamped to 0 (most negative " +
                           std::to_string(report.mostNegative) + ")");
      if (grid->empty()) {
        warnings.push_back(d.file + ": grid '" + d.grid + "' has no active voxels: empty medium");
        continue;
      }
      // The bound of a homogeneous medium's coefficients: beyond it (up to the float
      // overflow of 3e38 x 2) tracking and the solvers stop meaning anything.
      const float peak = grid->maxValue();
      if (!(static_cast<double>(peak) * d.densityScale <= 1e9))
        throw InputError(d.file, d.field + ".density_scale",
                         "density up to " + std::to_string(peak) + " x density_scale " +
                             std::to_string(d.densityScale) +
                             " exceeds sigma_t = 1e9 per unit, the bound of any medium");
      m.type = MediumType::Vdb;
      m.bounds = grid->worldBounds();
      m.density = grid;
      m.densityScale = d.densityScale;
      m.majorantLevel = grid->cheapestMajorantLevel(d.densityScale, interpolation);
      m.albedo = d.albedo;
      m.emission = d.emission;
      if (!d.emissionGrid.empty()) {
        GridLoadReport emissionReport;
        m.emissionGrid = std::make_shared<SparseGrid>(
            loadVdbGrid(d.file, d.emissionGrid, d.transform, d.field + ".emission_grid",
                        emissionReport, reserve(d.field + ".emission_grid", d.emissionGrid)));
      }
      if (!d.temperatureGrid.empty()) {
        GridLoadReport temperatureReport;
        m.temperatureGrid = std::make_shared<SparseGrid>(loadVdbGrid(
            d.file, d.temperatureGrid, d.transform, d.field + ".temperature_grid",
            temperatureReport, reserve(d.field + ".temperature_grid", d.temperatureGrid)));
        m.temperature = d.temperature;
        m.blackbodyIntensity = d.blackbodyIntensity;
        m.blackbody =
            std::make_shared<BlackbodyTable>(d.temperature * m.temperatureGrid->maxValue());
      }
      warnUnusedGrids(d, warnings);
    } else {
      m = boxMedium(d);
    }
    m.interpolation = interpolation;
    m.phase = PhaseFunction::make(d.phase, d.g);
    set.media_.push_back(std::move(m));
  }
  return set;
}

bool MediaSet::allHomogeneous() const {
  return std::all_of(media_.begin(), media_.end(), [](const Medium& m) { return m.homogeneous(); });
}

MediumCoefficients MediaSet::at(const Vec3& p) const {
  MediumCoefficients sum;
  for (const Medium& m : media_) {
    if (!m.bounds.contains(p)) continue;
    const MediumCoefficients c = m.at(p);
    sum.sigmaA += c.sigmaA;
    sum.sigmaS += c.sigmaS;
    sum.source += c.source;
  }
  return sum;
}

RGB MediaSet::heterogeneousSigmaT(const Vec3& p, bool reduced) const {
  RGB sigmaT(0.0f);
  for (const Medium& m : media_) {
    if (m.homogeneous() || !m.bounds.contains(p)) continue;
    const MediumCoefficients c = m.at(p);
    sigmaT += reduced ? c.sigmaT() - c.sigmaS * m.phase.truncated(kShBands).forward : c.sigmaT();
  }
  return sigmaT;
}

RGB MediaSet::homogeneousOpticalDepth(const Ray& ray, float tmin, float tmax, bool reduced) const {
  RGB tau(0.0f);
  thread_local std::vector<std::pair<float, float>> spans;
  for (const Medium& m : media_) {
    if (!m.homogeneous()) continue;
    spans.clear();
    m.intervals(ray, tmin, tmax, spans);
    const RGB sigmaT =
        reduced ? m.majorant() - m.sigmaS * m.phase.truncated(kShBands).forward : m.majorant();
    for (const auto& [a, b] : spans) tau += sigmaT * (b - a);
  }
  return tau;
}

void MediaSet::heterogeneousIntervals(const Ray& ray, float tmin, float tmax,
                                      std::vector<std::pair<float, float>>& out) const {
  const size_t first = out.size();
  for (const Medium& m : media_)
    if (!m.homogeneous()) m.intervals(ray, tmin, tmax, out);
  std::vector<std::pair<float, float>> mine(out.begin() + static_cast<ptrdiff_t>(first), out.end());
  mergeIntervals(mine);
  out.resize(first);
  out.insert(out.end(), mine.begin(), mine.end());
}

void mergeIntervals(std::vector<std::pair<float, float>>& v) {
  std::sort(v.begin(), v.end());
  size_t w = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (w > 0 && v[i].first <= v[w - 1].second)
      v[w - 1].second = std::max(v[w - 1].second, v[i].second);
    else
      v[w++] = v[i];
  }
  v.resize(w);
}

void MediaSet::intervals(const Ray& ray, float tmin, float tmax,
                         std::vector<std::pair<float, float>>& out) const {
  const size_t first = out.size();
  for (const Medium& m : media_) m.intervals(ray, tmin, tmax, out);
  if (media_.size() > 1) {
    std::vector<std::pair<float, float>> mine(out.begin() + static_cast<ptrdiff_t>(first),
                                              out.end());
    mergeIntervals(mine);
    out.resize(first);
    out.insert(out.end(), mine.begin(), mine.end());
  }
}

Bounds3 MediaSet::bounds() const {
  Bounds3 b;
  for (const Medium& m : media_) b.extend(m.bounds);
  return b;
}

size_t MediaSet::memoryBytes() const {
  size_t bytes = 0;
  for (const Medium& m : media_) bytes += m.memoryBytes();
  return bytes;
}

}  // namespace lvox
