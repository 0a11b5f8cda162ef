// Reads one float grid of an OpenVDB file and checks it (errors name the file and field).
#include "volume/media/vdb_loader.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Statistics.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include "src/core/error.h"
#include "volume/media/sparse_grid_trees.h"
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

std::string listGrids(const openvdb::GridPtrVec& grids) {  // metadata-only grids
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

// An Int64 metadata value of a grid, -1 when it has none.
int64_t int64Meta(const openvdb::GridBase& grid, const char* key) {
  const auto value = grid.getMetadata<openvdb::Int64Metadata>(key);
  return value ? value->value() : -1;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> listVdbGrids(const std::string& file) {
  std::vector<std::pair<std::string, std::string>> out;
  try {
    initOpenVdb();
    openvdb::io::File vdb(file);
    vdb.open(false);
    const openvdb::GridPtrVecPtr grids = vdb.readAllGridMetadata();  // held: the loop reads it
    for (const auto& g : *grids) out.emplace_back(g->getName(), g->valueType());
    vdb.close();
  } catch (const std::exception&) {
    out.clear();
  }
  return out;
}

uint64_t estimatedTreeBytes(int64_t fileMemBytes, int64_t fileVoxelCount, uint64_t fileBytes) {
  if (fileMemBytes > 0) return static_cast<uint64_t>(fileMemBytes);
  if (fileVoxelCount > 0) return static_cast<uint64_t>(fileVoxelCount) * sizeof(float);
  return fileBytes;  // compressed values: a lower bound
}

SparseGrid loadVdbGrid(const std::string& file, const std::string& gridName,
                       const Transform& sceneTransform, const std::string& field,
                       GridLoadReport& report,
                       const std::function<void(uint64_t bytes)>& beforeReading) {
  {
    std::ifstream probe(file, std::ios::binary);
    if (!probe) throw InputError(file, field, std::string("cannot open: ") + std::strerror(errno));
  }
  // OpenVDB trusts the file's lengths, counts and compressed blocks: walk them first.
  const VdbTreeShape shape = precheckVdbFile(file, field, gridName);
  initOpenVdb();
  openvdb::GridBase::Ptr base;
  try {
    openvdb::io::File vdb(file);
    vdb.open(false);  // no delayed loading: a truncated file fails here, not later
    // The names and types first (no trees), then only the asked grid: a Blender cache
    // holds density, flame, temperature and velocity grids of similar sizes.
    const openvdb::GridPtrVec metadata = *vdb.readAllGridMetadata();
    int matches = 0;
    for (const auto& g : metadata) matches += g->getName() == gridName ? 1 : 0;
    if (matches == 0)
      throw InputError(file, field,
                       "no grid named '" + gridName + "'; the file has " + listGrids(metadata));
    if (matches > 1)
      throw InputError(
          file, field,
          "the name '" + gridName + "' is used by " + std::to_string(matches) + " grids");
    for (const auto& g : metadata) {
      if (g->getName() != gridName) continue;
      if (!g->isType<openvdb::FloatGrid>())
        throw InputError(file, field,
                         "grid '" + gridName + "' holds " + g->valueType() +
                             " values; a density needs a float grid");
      if (beforeReading)
        beforeReading(
            std::max(shape.bytes(),
                     estimatedTreeBytes(int64Meta(*g, openvdb::GridBase::META_FILE_MEM_BYTES),
                                        int64Meta(*g, openvdb::GridBase::META_FILE_VOXEL_COUNT),
                                        std::filesystem::file_size(file))));
    }
    base = vdb.readGrid(gridName);
    vdb.close();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file, field, "not a readable OpenVDB file: " + clamp(e.what()));
  }
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

  Transform gridMap;
  try {
    // OpenVDB throws ArithmeticError for a singular map stored in the file (found by
    // fuzzing): an input error like any other.
    gridMap = fromVdbMatrix(grid->transform().baseMap()->getAffineMap()->getMat4());
  } catch (const std::exception& e) {
    throw InputError(file, field,
                     "grid '" + gridName + "' has an unusable transform: " + clamp(e.what()));
  }
  const Transform indexToWorld = sceneTransform * gridMap;
  const float det = indexToWorld.determinant3();
  if (!std::isfinite(det) || std::abs(det) < 1e-30f)
    throw InputError(file, field, "the grid's transform is singular");

  report.activeVoxels = grid->activeVoxelCount();
  if (report.activeVoxels == 0) return SparseGrid();  // empty medium: the caller warns
  return SparseGrid(buildSparseTrees(grid, file, field, report), indexToWorld);
}

}  // namespace lvox
