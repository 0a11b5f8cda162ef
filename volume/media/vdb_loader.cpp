// The only translation unit that includes OpenVDB: reads a float grid into a DenseGrid.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Statistics.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

#include "src/core/error.h"
#include "volume/media/dense_grid.h"
#include "volume/media/vdb_precheck.h"

namespace lvox {
namespace {

std::string clamp(std::string s) {
  // OpenVDB messages can carry text read from the file: keep one short line.
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s.size() > 200 ? s.substr(0, 200) + "..." : s;
}

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string listGrids(const openvdb::GridPtrVec& grids) {
  std::ostringstream s;
  for (size_t i = 0; i < grids.size(); ++i)
    s << (i ? ", " : "") << "'" << grids[i]->getName() << "' (" << grids[i]->valueType() << ")";
  return grids.empty() ? "none" : s.str();
}

Transform fromVdbMatrix(const openvdb::Mat4d& m) {
  // OpenVDB multiplies row vectors (p' = p M); lvox's Transform acts on column vectors.
  Transform t;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) t.m[r][c] = static_cast<float>(m(c, r));
  return t;
}

}  // namespace

DenseGrid loadVdbGrid(const std::string& file, const std::string& gridName,
                      const Transform& sceneTransform, const std::string& field,
                      GridLoadReport& report) {
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) throw InputError(file, field, std::string("cannot open: ") + std::strerror(errno));
  }
  // OpenVDB allocates whatever the file's lengths say: check them against its size first.
  precheckVdbFile(file, field);
  initOpenVdb();
  openvdb::GridPtrVec grids;
  try {
    openvdb::io::File vdb(file);
    vdb.open(false);  // no delayed loading: a truncated file fails here, not later
    grids = *vdb.getGrids();
    vdb.close();
  } catch (const std::exception& e) {
    throw InputError(file, field, "not a readable OpenVDB file: " + clamp(e.what()));
  }
  openvdb::GridBase::Ptr base;
  int matches = 0;
  for (const auto& g : grids)
    if (g->getName() == gridName) {
      base = g;
      ++matches;
    }
  if (!base)
    throw InputError(file, field,
                     "no grid named '" + gridName + "'; the file has " + listGrids(grids));
  if (matches > 1)
    throw InputError(
        file, field,
        "the name '" + gridName + "' is used by " + std::to_string(matches) + " grids");
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid)
    throw InputError(file, field,
                     "grid '" + gridName + "' holds " + base->valueType() +
                         " values; a density needs a float grid");
  if (grid->getGridClass() == openvdb::GRID_LEVEL_SET)
    throw InputError(file, field,
                     "grid '" + gridName + "' is a level set (a signed distance), not a density");
  if (!grid->transform().isLinear())
    throw InputError(file, field, "grid '" + gridName + "' has a non-linear (frustum) transform");
  if (!std::isfinite(grid->background()))
    throw InputError(file, field, "grid '" + gridName + "' has a non-finite background value");

  DenseGrid dense;
  Transform gridMap;
  try {
    // OpenVDB throws ArithmeticError for a singular map stored in the file (found by
    // fuzzing): an input error like any other.
    gridMap = fromVdbMatrix(grid->transform().baseMap()->getAffineMap()->getMat4());
  } catch (const std::exception& e) {
    throw InputError(file, field,
                     "grid '" + gridName + "' has an unusable transform: " + clamp(e.what()));
  }
  dense.indexToWorld = sceneTransform * gridMap;
  const float det = dense.indexToWorld.determinant3();
  if (!std::isfinite(det) || std::abs(det) < 1e-30f)
    throw InputError(file, field, "the grid's transform is singular");
  dense.worldToIndex = dense.indexToWorld.inverse();

  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  report.activeVoxels = grid->activeVoxelCount();
  if (report.activeVoxels == 0 || box.empty()) return dense;  // empty medium: caller warns
  const openvdb::Coord dim = box.dim();
  const uint64_t count = static_cast<uint64_t>(dim.x()) * dim.y() * dim.z();
  if (count > (1ull << 29))
    throw InputError(file, field,
                     "the active box of " + std::to_string(count) +
                         " voxels exceeds the limit of 2^29 (2 GiB as floats)");
  dense.nx = dim.x();
  dense.ny = dim.y();
  dense.nz = dim.z();
  dense.origin = Imath::V3i(box.min().x(), box.min().y(), box.min().z());
  dense.values.assign(count, 0.0f);
  uint64_t nonFinite = 0;
  for (auto it = grid->cbeginValueOn(); it; ++it) {
    const openvdb::CoordBBox vbox = it.getBoundingBox();  // one voxel, or a whole tile
    float v = *it;
    if (!std::isfinite(v)) {
      nonFinite += vbox.volume();
      continue;
    }
    if (v < 0.0f) {
      report.clampedNegative += vbox.volume();
      report.mostNegative = std::min(report.mostNegative, v);
      v = 0.0f;
    }
    for (int z = vbox.min().z(); z <= vbox.max().z(); ++z)
      for (int y = vbox.min().y(); y <= vbox.max().y(); ++y)
        for (int x = vbox.min().x(); x <= vbox.max().x(); ++x) {
          const size_t idx =
              (static_cast<size_t>(z - dense.origin.z) * dense.ny + (y - dense.origin.y)) *
                  dense.nx +
              static_cast<size_t>(x - dense.origin.x);
          dense.values[idx] = v;
        }
    dense.maxValue = std::max(dense.maxValue, v);
  }
  if (nonFinite > 0)
    throw InputError(file, field, std::to_string(nonFinite) + " active voxels are NaN or infinite");

  // Occupied blocks from the tree itself: active leaves and tiles, dilated by one block.
  dense.bx = (dense.nx + DenseGrid::kBlock - 1) / DenseGrid::kBlock;
  dense.by = (dense.ny + DenseGrid::kBlock - 1) / DenseGrid::kBlock;
  dense.bz = (dense.nz + DenseGrid::kBlock - 1) / DenseGrid::kBlock;
  std::vector<uint8_t> raw(static_cast<size_t>(dense.bx) * dense.by * dense.bz, 0);
  auto markBox = [&](const openvdb::CoordBBox& b) {
    const int k = DenseGrid::kBlock;
    for (int z = (b.min().z() - dense.origin.z) / k; z <= (b.max().z() - dense.origin.z) / k; ++z)
      for (int y = (b.min().y() - dense.origin.y) / k; y <= (b.max().y() - dense.origin.y) / k; ++y)
        for (int x = (b.min().x() - dense.origin.x) / k; x <= (b.max().x() - dense.origin.x) / k;
             ++x)
          if (x >= 0 && y >= 0 && z >= 0 && x < dense.bx && y < dense.by && z < dense.bz)
            raw[(static_cast<size_t>(z) * dense.by + y) * dense.bx + x] = 1;
  };
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf)
    if (leaf->onVoxelCount() > 0) markBox(leaf->getNodeBoundingBox());
  for (auto tile = grid->cbeginValueOn(); tile; ++tile)
    if (!tile.isVoxelValue()) markBox(tile.getBoundingBox());
  dense.blockOccupied = raw;
  for (int z = 0; z < dense.bz; ++z)
    for (int y = 0; y < dense.by; ++y)
      for (int x = 0; x < dense.bx; ++x) {
        if (!raw[(static_cast<size_t>(z) * dense.by + y) * dense.bx + x]) continue;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if (X >= 0 && Y >= 0 && Z >= 0 && X < dense.bx && Y < dense.by && Z < dense.bz)
                dense.blockOccupied[(static_cast<size_t>(Z) * dense.by + Y) * dense.bx + X] = 1;
            }
      }
  dense.computeBlockMax();
  return dense;
}

}  // namespace lvox
