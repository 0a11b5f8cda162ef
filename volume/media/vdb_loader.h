#pragma once
// Reading a float grid of an OpenVDB file into a SparseGrid (the tree as stored, no copy).
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "src/core/math.h"
#include "volume/media/sparse_grid.h"

namespace lvox {

struct GridLoadReport {
  uint64_t clampedNegative = 0;
  float mostNegative = 0.0f;
  uint64_t activeVoxels = 0;
  size_t treeBytes = 0;  // the value tree as OpenVDB holds it (memUsage)
};

// Loads the float grid `gridName` of `file` (errors name `field`, e.g. "media[0].grid"),
// composing its own index->world map with `sceneTransform`. Only that grid is read. Errors:
// missing or corrupt file, missing grid (lists the grids), non-float or level-set grid,
// non-linear map, NaN/Inf values.
// The grids of `file` as (name, value type), read from their metadata only; empty when the
// file cannot be read (loadVdbGrid reports that).
std::vector<std::pair<std::string, std::string>> listVdbGrids(const std::string& file);

// `beforeReading(bytes)` is called with the memory the grid's tree will take before the
// tree is read: the larger of the nodes the precheck counted (vdb_precheck.h) and the
// file's own statistics (OpenVDB writes `file_mem_bytes` with every grid; else the active
// voxel count x 4 bytes, else the file size). A budget check that throws stops the load
// before OpenVDB allocates anything, whatever the statistics say.
SparseGrid loadVdbGrid(const std::string& file, const std::string& gridName,
                       const Transform& sceneTransform, const std::string& field,
                       GridLoadReport& report,
                       const std::function<void(uint64_t bytes)>& beforeReading = {});

// The memory a grid's tree takes once read, from its metadata (see loadVdbGrid): the
// file's `file_mem_bytes`, else `file_voxel_count` x 4 bytes, else the file's size (each
// negative when the file has none).
uint64_t estimatedTreeBytes(int64_t fileMemBytes, int64_t fileVoxelCount, uint64_t fileBytes);

}  // namespace lvox
