#pragma once
// The lit surfaces as lights for the final gathers (multiple importance sampling, Veach
// 1995). A final gather's cosine rays find a small bright patch (the ceiling above a lamp,
// the wall behind it, a sunlit spot) by chance, a few of 64 rays, and that noise was the
// largest term of four scenes' error (docs/results.md, stop 45). Here every triangle is cut
// into m x m equal cells; each side of a cell that sends light (its cloud radiance times
// its area) is a light, and a share of each gather's rays aims at points of lights drawn
// for that gather. Both kinds of ray weigh the surface they reach by the balance
// heuristic, so the estimate is the same integral as the cosine rays' alone: what the
// gather reaches, never what the lights' power says.
//
// Drawn by power alone, the same for every receiver, the lights sent rays at surfaces
// behind the receiver or far from it (Sponza's indirect noise 1.62 % against 1.54 % with
// the weights below, docs/pcb.md). So the lights are grouped into up to kMaxRegions
// regions (by the axis their side faces, then split at the median along the longest side
// of their box), each with its box, power and the cone of its sides' normals, and every
// gather first weighs the regions by how much light they could send it: power times the
// bounds of the cosines at both ends over the distance squared (the light-tree importance
// of Conty Estevez and Kulla 2018, as pbrt-v4's BVHLightSampler bounds it), then draws a
// light of the region by power. Occlusion is not known; MIS keeps it from costing bias.
//
// The lights only choose directions: their power is estimated once (at each cell's centre,
// from the surfel that stands for it and the delta lights' light there), and any error in
// it costs variance, not bias.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "src/core/math.h"
#include "src/world/world.h"

namespace lvox {

class PointCloud;
struct GatherOptions;

class GatherLightCells {
 public:
  static constexpr int kMaxRegions = 512;

  struct Sample {
    uint32_t triangle = 0;
    float b1 = 0.0f, b2 = 0.0f;  // barycentrics of the triangle's second and third vertex
    Vec3 point;
    Vec3 normal;  // unit normal of the lit side
    float pdfArea = 0.0f;
  };

  // The regions weighed for one receiver: a gather's distribution over them.
  class View {
   public:
    bool empty() const { return !(cdf_[static_cast<size_t>(regions_)] > 0.0f); }

   private:
    friend class GatherLightCells;
    int regions_ = 0;
    std::array<float, kMaxRegions + 1> cdf_{};  // normalised when not empty
  };

  GatherLightCells() = default;
  // Cells at most about `step` across (slivers get the cells of a triangle of their area
  // with equal sides, four times over at most). `options` gives the surfel that stands for
  // a point (GatherOptions::surfelAt) and the delta lights' light there (hitLight): the
  // gathers' own view of the surfaces, so that the power follows what they will reach.
  GatherLightCells(const TriangleMesh& mesh, const PointCloud& cloud, const GatherOptions& options,
                   float step);

  // True when no cell sends any light: the gathers then send no rays at cells.
  bool empty() const { return regions_.empty(); }
  size_t cells() const { return cells_; }
  size_t lights() const { return entryKey_.size(); }
  size_t regions() const { return regions_.size(); }

  // The regions' weights for a receiver at p with unit normal n.
  View view(const Vec3& p, const Vec3& n) const;
  // A point of region `region`'s lights, drawn by power (u1) and uniformly in its cell;
  // its pdfArea is the density given the region.
  Sample pointOf(uint32_t region, float u1, float u2, float u3) const;
  // A point on a lit side drawn with density pdfArea (per unit area) for that view: u1
  // picks the region, u2 the light in it, u3 and u4 the point in its cell. A view without
  // weight gives a sample of pdfArea 0.
  Sample sample(const View& view, float u1, float u2, float u3, float u4) const;
  // The density at a point of triangle `triangle` at barycentrics (b1, b2), on the side
  // that faces `towards` (a direction from the point): per unit area.
  float pdfArea(const View& view, uint32_t triangle, float b1, float b2, const Vec3& towards) const;
  size_t memoryBytes() const;
  // The cells of a mesh at that step, and the bytes of that many cells over that many
  // triangles, at most (before they are built, for the memory budget).
  static size_t cellsFor(const TriangleMesh& mesh, float step);
  static size_t bytesFor(size_t cells, size_t triangles);

  // The cell of barycentrics (b1, b2) among a triangle's m x m: cells (i, j) with
  // i + j <= m - 1 point their corner (i, j) at vertex 0's side ("lower", m (m + 1) / 2 of
  // them, first), the others (i, j), i + j <= m - 2, the opposite way.
  static uint32_t cellOf(uint32_t m, float b1, float b2);
  static uint32_t divisionsOf(const Vec3& a, const Vec3& b, const Vec3& c, float step);

 private:
  static constexpr uint32_t kNone = ~0u;
  struct Triangle {
    uint32_t first = 0;  // its first cell
    uint32_t m = 1;      // divisions of each edge: m * m cells
    float cellArea = 0.0f;
    Vec3 normal;  // unit geometric normal (side 0 faces it, side 1 away)
  };
  struct Region {
    Vec3 centre;
    float radius = 0.0f;                       // half the box's diagonal
    Vec3 axis;                                 // of the sides' normals
    float cosSpread = 1.0f, sinSpread = 0.0f;  // the cone's half angle about the axis
    float power = 0.0f;
    uint32_t first = 0, end = 0;  // its lights
  };
  float importance(const Region& r, const Vec3& p, const Vec3& n) const;
  // The point of barycentrics (beta1, beta2) in cell `cell` of triangle t.
  Sample pointIn(uint32_t t, uint32_t cell, float beta1, float beta2) const;
  uint32_t triangleOfCell(uint32_t cell) const;
  // A light's density over its cell's area given its region: its share of the region's power.
  double densityInRegion(uint32_t entry, float cellArea) const;
  void buildRegions(const std::vector<Vec3>& position, const std::vector<Vec3>& normal,
                    const std::vector<float>& power, const std::vector<uint32_t>& key);

  const TriangleMesh* mesh_ = nullptr;
  size_t cells_ = 0;
  std::vector<Triangle> triangles_;
  // The lights, region by region: cell * 2 + side, and the power summed up to each.
  std::vector<uint32_t> entryKey_;
  std::vector<double> entryCdf_;       // lights() + 1 entries
  std::vector<uint32_t> entryOfSide_;  // per cell * 2 + side: its light, or kNone
  std::vector<uint32_t> regionOf_;     // per light
  std::vector<Region> regions_;
};

}  // namespace lvox
