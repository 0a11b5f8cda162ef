#include "src/render/cloud_exchange.h"

#include <algorithm>
#include <stdexcept>

#include "src/core/byte_blocks.h"

namespace lvox {
namespace {

// The fields of a surfel slice, in this order; change it with the fields.
constexpr uint32_t kSurfelLayout = 1;
// The fields of a rank's lvoxels: per medium its grid, then its arrays.
constexpr uint32_t kLvoxelLayout = 2;

struct LvoxelShare {
  LvoxelGrid grid;
  std::vector<Vec3> position;
  std::vector<float> halfSize;
  std::vector<RGB> sigmaA, sigmaS, emission;  // emission: empty when the medium emits not
  std::vector<int64_t> cell;
};

}  // namespace

std::vector<size_t> triangleSlices(const TriangleMesh& mesh, int ranks) {
  const size_t n = mesh.triangleCount();
  const auto parts = static_cast<size_t>(std::max(1, ranks));
  std::vector<double> prefix(n + 1, 0.0);
  for (size_t t = 0; t < n; ++t)
    prefix[t + 1] = prefix[t] + 0.5 * length(cross(mesh.vertex(t, 1) - mesh.vertex(t, 0),
                                                   mesh.vertex(t, 2) - mesh.vertex(t, 0)));
  std::vector<size_t> first(parts + 1, n);
  first[0] = 0;
  for (size_t r = 1; r < parts; ++r) {
    const double target = prefix[n] * static_cast<double>(r) / static_cast<double>(parts);
    first[r] = static_cast<size_t>(std::lower_bound(prefix.begin(), prefix.end(), target) -
                                   prefix.begin());
    first[r] = std::clamp(first[r], first[r - 1], n);
  }
  return first;
}

std::string surfelsToBytes(const SurfelSet& s) {
  ByteBlockWriter w(kSurfelLayout);
  w.value(s.radiusScale);
  w.array(s.position);
  w.array(s.normal);
  w.array(s.radius);
  w.array(s.albedo);
  w.array(s.triangle);
  w.array(s.clip);
  w.array(s.enclosedSides);
  return w.take();
}

void appendSurfelsFromBytes(const std::string& bytes, const std::string& from, SurfelSet& out) {
  ByteBlockReader r(bytes, kSurfelLayout, from);
  const auto radiusScale = r.value<float>();
  SurfelSet s;
  r.array(s.position, "surfel positions");
  r.array(s.normal, "surfel normals");
  r.array(s.radius, "surfel radii");
  r.array(s.albedo, "surfel albedos");
  r.array(s.triangle, "surfel triangles");
  r.array(s.clip, "surfel clips");
  r.array(s.enclosedSides, "surfel enclosed sides");
  r.finish();
  const size_t n = s.position.size();
  for (size_t size : {s.normal.size(), s.radius.size(), s.albedo.size(), s.triangle.size(),
                      s.clip.size(), s.enclosedSides.size()})
    if (size != n)
      throw std::runtime_error("the surfels received from " + from + ": arrays of " +
                               std::to_string(size) + " and " + std::to_string(n) + " elements");
  if (n == 0) return;
  if (out.size() == 0) out.radiusScale = radiusScale;
  auto cat = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
  cat(out.position, s.position);
  cat(out.normal, s.normal);
  cat(out.radius, s.radius);
  cat(out.albedo, s.albedo);
  cat(out.triangle, s.triangle);
  cat(out.clip, s.clip);
  cat(out.enclosedSides, s.enclosedSides);
  out.radianceFront.resize(out.position.size(), RGB(0.0f));
  out.radianceBack.resize(out.position.size(), RGB(0.0f));
}

SurfelSet allgatherSurfels(SurfelSet slice, Collective& team) {
  if (!team.distributed()) return slice;
  std::string mine = surfelsToBytes(slice);
  const float radiusScale = slice.radiusScale;
  slice = SurfelSet();  // the bytes hold it now
  std::vector<std::string> all = team.allgather(mine);
  mine.clear();
  mine.shrink_to_fit();
  if (all.size() != static_cast<size_t>(team.size()))
    throw std::runtime_error("surfel exchange: " + std::to_string(all.size()) + " slices for " +
                             std::to_string(team.size()) + " ranks");
  SurfelSet whole;
  whole.radiusScale = radiusScale;
  for (size_t r = 0; r < all.size(); ++r) {
    appendSurfelsFromBytes(all[r], "rank " + std::to_string(r), whole);
    std::string().swap(all[r]);  // freed as soon as it is read
  }
  return whole;
}

std::vector<LvoxelSet> allgatherLvoxels(const std::vector<LvoxelSet>& shares, Collective& team) {
  ByteBlockWriter w(kLvoxelLayout);
  w.value(static_cast<uint64_t>(shares.size()));
  for (const LvoxelSet& l : shares) {
    w.value(l.light.grid());
    w.array(l.position);
    w.array(l.halfSize);
    w.array(l.sigmaA);
    w.array(l.sigmaS);
    w.array(l.emission);
    std::vector<int64_t> cells(l.size());
    for (size_t i = 0; i < l.size(); ++i) cells[i] = l.light.cellOfSlot(l.slot[i]);
    w.array(cells);
  }
  const std::vector<std::string> all = team.allgather(w.take());
  // Each rank's shares, read and checked.
  std::vector<std::vector<LvoxelShare>> ranks(all.size());
  for (size_t r = 0; r < all.size(); ++r) {
    const std::string from = "rank " + std::to_string(r);
    ByteBlockReader reader(all[r], kLvoxelLayout, from);
    const auto media = reader.value<uint64_t>();
    if (media != shares.size())
      throw std::runtime_error("the lvoxels received from " + from + ": " + std::to_string(media) +
                               " media, expected " + std::to_string(shares.size()));
    ranks[r].resize(shares.size());
    for (size_t m = 0; m < shares.size(); ++m) {
      LvoxelShare& s = ranks[r][m];
      s.grid = reader.value<LvoxelGrid>();
      reader.array(s.position, "lvoxel positions");
      reader.array(s.halfSize, "lvoxel sizes");
      reader.array(s.sigmaA, "lvoxel sigma_a");
      reader.array(s.sigmaS, "lvoxel sigma_s");
      reader.array(s.emission, "lvoxel emission");
      reader.array(s.cell, "lvoxel cells");
      const size_t n = s.position.size();
      if (s.halfSize.size() != n || s.sigmaA.size() != n || s.sigmaS.size() != n ||
          s.cell.size() != n || (!s.emission.empty() && s.emission.size() != n))
        throw std::runtime_error("the lvoxels received from " + from +
                                 ": arrays of different lengths");
      if (n > 0 && !(s.grid == shares[m].light.grid()) && shares[m].size() > 0)
        throw std::runtime_error("the lvoxels received from " + from + ": another grid");
    }
    reader.finish();
  }
  // Per medium, the shares merged by cell (each cell is one rank's: distinct, ascending).
  std::vector<LvoxelSet> whole(shares.size());
  for (size_t m = 0; m < shares.size(); ++m) {
    const LvoxelShare* withGrid = nullptr;
    size_t total = 0;
    for (const auto& rank : ranks) {
      total += rank[m].position.size();
      if (!rank[m].position.empty()) withGrid = &rank[m];
    }
    if (!withGrid) continue;
    LvoxelSet& out = whole[m];
    out.light = LvoxelLight(withGrid->grid);
    std::vector<size_t> next(ranks.size(), 0);
    for (size_t k = 0; k < total; ++k) {
      size_t best = ranks.size();
      for (size_t r = 0; r < ranks.size(); ++r) {
        const LvoxelShare& s = ranks[r][m];
        if (next[r] < s.cell.size() &&
            (best == ranks.size() || s.cell[next[r]] < ranks[best][m].cell[next[best]]))
          best = r;
      }
      const LvoxelShare& s = ranks[best][m];
      const size_t i = next[best]++;
      out.position.push_back(s.position[i]);
      out.halfSize.push_back(s.halfSize[i]);
      out.sigmaA.push_back(s.sigmaA[i]);
      out.sigmaS.push_back(s.sigmaS[i]);
      if (!s.emission.empty()) {
        out.emission.resize(out.position.size() - 1, RGB(0.0f));
        out.emission.push_back(s.emission[i]);
      }
      if (s.cell[i] < 0 || static_cast<double>(s.cell[i]) >= s.grid.cellCount())
        throw std::runtime_error("the lvoxels received from rank " + std::to_string(best) +
                                 ": cell " + std::to_string(s.cell[i]) + " outside the grid");
      out.slot.push_back(out.light.occupy(static_cast<long>(s.cell[i])));
    }
    if (!out.emission.empty()) out.emission.resize(out.position.size(), RGB(0.0f));
  }
  return whole;
}

}  // namespace lvox
