#include "volume/media/sparse_grid.h"

#include <array>
#include <cmath>

#include "src/core/rng.h"
#include "src/core/sampling.h"
#include "volume/media/sparse_grid_trees.h"

namespace lvox {
namespace {

using LeafT = openvdb::FloatTree::LeafNodeType;
constexpr int kLeafMask = static_cast<int>(LeafT::DIM) - 1;
constexpr int kLeafLog2 = static_cast<int>(LeafT::LOG2DIM);

// The voxels of one leaf's region: the leaf's buffer, or one value where a tile or the
// background covers the region.
struct LeafView {
  const float* data;
  float tile;
  float at(int i, int j, int k) const {
    return data ? data[((i & kLeafMask) << (2 * kLeafLog2)) | ((j & kLeafMask) << kLeafLog2) |
                       (k & kLeafMask)]
                : tile;
  }
};

// The leaf region each thread used last, in a plain thread-local (constant-initialised: no
// guard on access), so lookups along a ray, which mostly stay in one leaf, cost a compare
// before reading the buffer; the lower-node index is asked only when the region changes.
struct LeafEntry {
  uint64_t id;
  int x, y, z;
  const float* data;
  float tile;
};
thread_local LeafEntry lastLeaf{};

// The leaf region holding voxel (i, j, k), found through the lower-node index.
LeafView findLeaf(const SparseGrid::Trees& trees, int i, int j, int k) {
  using LowerT = LowerNodeIndex::LowerT;
  if (trees.leafTable)
    if (const float* data = trees.leafTable->find(i, j, k)) return {data, 0.0f};
  const openvdb::Coord c(i, j, k);
  if (const LowerT* lower = trees.lowerNodes->find(i, j, k)) {
    const openvdb::Index n = LowerT::coordToOffset(c);
    const auto& entry = lower->getTable()[n];
    if (lower->isChildMaskOn(n)) return {entry.getChild()->buffer().data(), 0.0f};
    return {nullptr, entry.getValue()};
  }
  if (!trees.lowerNodes->valuesOutside()) return {nullptr, 0.0f};
  // An upper node's or the root's tile, or a leaf beyond the index's reach.
  const openvdb::FloatTree& tree = trees.values->tree();
  if (const LeafT* leaf = tree.probeConstLeaf(c)) return {leaf->buffer().data(), 0.0f};
  return {nullptr, tree.getValue(c)};
}

[[gnu::noinline]] LeafView refillLeaf(const SparseGrid::Trees& trees, int i, int j, int k) {
  const LeafView leaf = findLeaf(trees, i, j, k);
  lastLeaf = {trees.id, i & ~kLeafMask, j & ~kLeafMask, k & ~kLeafMask, leaf.data, leaf.tile};
  return leaf;
}

// The leaf region holding voxel (i, j, k).
inline LeafView leafAt(const SparseGrid::Trees& trees, int i, int j, int k) {
  if (lastLeaf.id == trees.id && lastLeaf.x == (i & ~kLeafMask) && lastLeaf.y == (j & ~kLeafMask) &&
      lastLeaf.z == (k & ~kLeafMask))
    return {lastLeaf.data, lastLeaf.tile};
  return refillLeaf(trees, i, j, k);
}

// The 2 x 2 x 2 leaf regions from the one at (x, y, z) (leaf-aligned) on, which each thread
// used last for a stencil that crosses leaves. A tricubic stencil crosses in 3 of 4 lookups
// (its 4 voxels fit a leaf's 8 at 5 of 8 offsets per axis); along a ray consecutive
// stencils mostly share the block, so a crossing costs a compare, not up to 8 leaf
// lookups, each evicting the last one's leaf (1.5x the dense array's time before).
struct LeafBlock {
  uint64_t id;
  int x, y, z;
  LeafView corner[8];  // corner (dx | dy << 1 | dz << 2), d in {0, 1} leaves
};
thread_local LeafBlock lastBlock{};

[[gnu::noinline]] void refillBlock(const SparseGrid::Trees& trees, int x, int y, int z) {
  lastBlock.id = trees.id;
  lastBlock.x = x;
  lastBlock.y = y;
  lastBlock.z = z;
  constexpr int kDim = kLeafMask + 1;
  for (int c = 0; c < 8; ++c)
    lastBlock.corner[c] =
        findLeaf(trees, x + (c & 1) * kDim, y + (c >> 1 & 1) * kDim, z + (c >> 2) * kDim);
}

// The voxels [x0, x0 + N) x [y0, y0 + N) x [z0, z0 + N) into v[z][y][x], N <= 8: from one
// leaf when the stencil fits it, else from the block of 8 around it.
template <int N>
void gatherStencil(const SparseGrid::Trees& trees, int x0, int y0, int z0, float (&v)[N][N][N]) {
  static_assert(N <= kLeafMask + 1);
  if ((x0 & kLeafMask) + N <= kLeafMask + 1 && (y0 & kLeafMask) + N <= kLeafMask + 1 &&
      (z0 & kLeafMask) + N <= kLeafMask + 1) {
    const LeafView leaf = leafAt(trees, x0, y0, z0);
    for (int k = 0; k < N; ++k)
      for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) v[k][j][i] = leaf.at(x0 + i, y0 + j, z0 + k);
    return;
  }
  const int bx = x0 & ~kLeafMask, by = y0 & ~kLeafMask, bz = z0 & ~kLeafMask;
  if (lastBlock.id != trees.id || lastBlock.x != bx || lastBlock.y != by || lastBlock.z != bz)
    refillBlock(trees, bx, by, bz);
  // Per axis: which leaf of the pair each tap falls in (bit of the corner index).
  int cx[N], cy[N], cz[N];
  for (int a = 0; a < N; ++a) {
    cx[a] = x0 + a - bx > kLeafMask ? 1 : 0;
    cy[a] = y0 + a - by > kLeafMask ? 2 : 0;
    cz[a] = z0 + a - bz > kLeafMask ? 4 : 0;
  }
  for (int k = 0; k < N; ++k)
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i)
        v[k][j][i] = lastBlock.corner[cx[i] | cy[j] | cz[k]].at(x0 + i, y0 + j, z0 + k);
}

// Uniform cubic B-spline weights for fractional position f in [0, 1) (taps -1..2).
void bsplineWeights(float f, float w[4]) {
  const float f2 = f * f, f3 = f2 * f;
  w[0] = (1.0f - 3.0f * f + 3.0f * f2 - f3) / 6.0f;
  w[1] = (4.0f - 6.0f * f2 + 3.0f * f3) / 6.0f;
  w[2] = (1.0f + 3.0f * f + 3.0f * f2 - 3.0f * f3) / 6.0f;
  w[3] = f3 / 6.0f;
}

// Index coordinates beyond this are outside any grid (and would overflow int casts).
constexpr float kIndexLimit = 1e9f;

// The edge of the cube a value at `depth` of a four-level tree stands for, in cells: a
// voxel (1), a tile of a lower internal node (a leaf), of an upper one (a lower node), of the
// root or the background (an upper node).
template <class TreeT>
int nodeCells(int depth) {
  using Upper = typename TreeT::RootNodeType::ChildNodeType;
  using Lower = typename Upper::ChildNodeType;
  switch (depth) {
    case 3:
      return 1;
    case 2:
      return static_cast<int>(TreeT::LeafNodeType::DIM);
    case 1:
      return static_cast<int>(Lower::DIM);
    default:
      return static_cast<int>(Upper::DIM);
  }
}

// Amanatides-Woo DDA over the cells of a majorant tree, hierarchical: a cell inside a tile
// or a missing node is walked as the whole node (one step across it, whatever its size).
// Cell c covers index space [c * size - 0.5, (c + 1) * size - 0.5). Calls
// emit(t0, t1, value) in ray order for every visited piece; returns the pieces visited.
template <class Emit>
uint64_t walkCells(const MajorantTree& tree, const openvdb::CoordBBox& cellBox, float size,
                   const Ray& indexRay, float tmin, float tmax, Emit&& emit) {
  if (cellBox.empty()) return 0;
  Ray r;
  r.origin = (indexRay.origin + Vec3(0.5f, 0.5f, 0.5f)) / size;
  r.dir = indexRay.dir / size;
  r.tmin = tmin;
  r.tmax = tmax;
  const int lo[3] = {cellBox.min().x(), cellBox.min().y(), cellBox.min().z()};
  const int hi[3] = {cellBox.max().x(), cellBox.max().y(), cellBox.max().z()};
  Bounds3 box;
  box.lo = Vec3(static_cast<float>(lo[0]), static_cast<float>(lo[1]), static_cast<float>(lo[2]));
  box.hi = Vec3(static_cast<float>(hi[0] + 1), static_cast<float>(hi[1] + 1),
                static_cast<float>(hi[2] + 1));
  float t0, t1;
  if (!box.intersect(r, t0, t1) || !(t1 > t0)) return 0;
  const Vec3 start = r.at(t0);
  int cell[3], step[3];
  float tNext[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(static_cast<int>(std::floor(start[a])), lo[a], hi[a]);
    const float d = r.dir[a];
    step[a] = d > 0.0f ? 1 : (d < 0.0f ? -1 : 0);
    tDelta[a] = step[a] != 0 ? 1.0f / std::abs(d) : kInf;
    const float boundary = static_cast<float>(cell[a] + (step[a] > 0 ? 1 : 0));
    tNext[a] = step[a] != 0 ? std::max(t0, t0 + (boundary - start[a]) / d) : kInf;
  }
  openvdb::tree::ValueAccessor<const MajorantTree, false> acc(tree);
  uint64_t visited = 0;
  float t = t0;
  while (t < t1) {
    const openvdb::Coord c(cell[0], cell[1], cell[2]);
    // Cells in leaves (where the medium is) cost one probe; only tiles and empty nodes ask
    // for their depth.
    int dim = 1;
    float value;
    if (const auto* leaf = acc.probeConstLeaf(c)) {
      value = leaf->getValue(c);
    } else {
      const int depth = acc.getValueDepth(c);
      value = depth < 0 ? 0.0f : acc.getValue(c);
      dim = nodeCells<MajorantTree>(depth);
    }
    // The node's far side: n[a] cells away along axis a; the axis crossed first leaves it.
    int n[3] = {0, 0, 0};
    float exit = kInf;
    int exitAxis = -1;
    for (int a = 0; a < 3; ++a) {
      if (step[a] == 0) continue;
      const int nodeLo = cell[a] & ~(dim - 1);
      n[a] = step[a] > 0 ? nodeLo + dim - cell[a] : cell[a] - nodeLo + 1;
      const float te = tNext[a] + static_cast<float>(n[a] - 1) * tDelta[a];
      if (te < exit) {
        exit = te;
        exitAxis = a;
      }
    }
    ++visited;
    const float end = std::min(exit, t1);
    if (end > t) emit(t, end, value);
    if (exitAxis < 0 || exit >= t1) break;
    // Cross the node: every other axis advances by the boundaries it crosses before `exit`
    // (staying inside the node), the exit axis by n.
    for (int a = 0; a < 3; ++a) {
      if (step[a] == 0 || a == exitAxis || tNext[a] >= exit) continue;
      const int k =
          std::min(n[a] - 1, static_cast<int>(std::floor((exit - tNext[a]) / tDelta[a])) + 1);
      cell[a] += step[a] * k;
      tNext[a] += static_cast<float>(k) * tDelta[a];
    }
    cell[exitAxis] += step[exitAxis] * n[exitAxis];
    tNext[exitAxis] += static_cast<float>(n[exitAxis]) * tDelta[exitAxis];
    t = std::max(t, exit);
    if (cell[exitAxis] < lo[exitAxis] || cell[exitAxis] > hi[exitAxis]) break;
  }
  return visited;
}

Ray toIndexRay(const Transform& worldToIndex, const Ray& ray) {
  Ray local;
  local.origin = worldToIndex.point(ray.origin);
  local.dir = worldToIndex.vector(ray.dir);  // not unit: t is preserved (affine map)
  return local;
}

// Relative costs of a majorant-tree cell step and of one tentative collision (a medium
// evaluation plus the tracking step) per interpolation, from lvox_sparse_lookups on the WDAS
// cloud (docs/results.md, "Sparse volumes"): a cell step 70-110 ns, lookups along rays
// 15-18 ns nearest, 41-55 ns trilinear, 128-135 ns tricubic, plus ~10 ns of tracking.
constexpr float kCellCost = 1.0f;
float lookupCost(Interpolation interp) {
  switch (interp) {
    case Interpolation::Nearest:
      return 0.3f;
    case Interpolation::Trilinear:
      return 0.6f;
    case Interpolation::Tricubic:
      return 1.6f;
  }
  return 0.6f;
}

}  // namespace

SparseGrid::SparseGrid(std::shared_ptr<const Trees> trees, const Transform& indexToWorld)
    : trees_(std::move(trees)), indexToWorld_(indexToWorld), worldToIndex_(indexToWorld.inverse()) {
  if (!trees_) return;
  maxValue_ = trees_->maxValue;
  const openvdb::CoordBBox& a = trees_->activeBox;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner(static_cast<float>(c & 1 ? a.max().x() + 2 : a.min().x() - 2),
                      static_cast<float>(c & 2 ? a.max().y() + 2 : a.min().y() - 2),
                      static_cast<float>(c & 4 ? a.max().z() + 2 : a.min().z() - 2));
    worldBounds_.extend(indexToWorld_.point(corner));
  }
}

uint64_t SparseGrid::activeVoxels() const { return trees_ ? trees_->activeVoxels : 0; }

float SparseGrid::voxel(int i, int j, int k) const {
  if (!trees_) return 0.0f;
  return leafAt(*trees_, i, j, k).at(i, j, k);
}

float SparseGrid::sampleIndex(const Vec3& p, Interpolation interp) const {
  if (!trees_ ||
      !(std::abs(p.x) < kIndexLimit && std::abs(p.y) < kIndexLimit && std::abs(p.z) < kIndexLimit))
    return 0.0f;
  switch (interp) {
    case Interpolation::Nearest: {
      const int i = static_cast<int>(std::floor(p.x + 0.5f));
      const int j = static_cast<int>(std::floor(p.y + 0.5f));
      const int k = static_cast<int>(std::floor(p.z + 0.5f));
      return leafAt(*trees_, i, j, k).at(i, j, k);
    }
    case Interpolation::Trilinear: {
      const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
      const int i = static_cast<int>(fx), j = static_cast<int>(fy), k = static_cast<int>(fz);
      const float tx = p.x - fx, ty = p.y - fy, tz = p.z - fz;
      float v[2][2][2];
      gatherStencil(*trees_, i, j, k, v);
      auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
      const float c00 = lerp(v[0][0][0], v[0][0][1], tx);
      const float c10 = lerp(v[0][1][0], v[0][1][1], tx);
      const float c01 = lerp(v[1][0][0], v[1][0][1], tx);
      const float c11 = lerp(v[1][1][0], v[1][1][1], tx);
      return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
    }
    case Interpolation::Tricubic: {
      // C2 cubic B-spline (approximating: it smooths the data slightly, which is the
      // point: solvers keep their order up to 4 on it).
      const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
      const int i = static_cast<int>(fx), j = static_cast<int>(fy), k = static_cast<int>(fz);
      float wx[4], wy[4], wz[4];
      bsplineWeights(p.x - fx, wx);
      bsplineWeights(p.y - fy, wy);
      bsplineWeights(p.z - fz, wz);
      float v[4][4][4];
      gatherStencil(*trees_, i - 1, j - 1, k - 1, v);
      float sum = 0.0f;
      for (int c = 0; c < 4; ++c) {
        float plane = 0.0f;
        for (int b = 0; b < 4; ++b) {
          float row = 0.0f;
          for (int a = 0; a < 4; ++a) row += wx[a] * v[c][b][a];
          plane += wy[b] * row;
        }
        sum += wz[c] * plane;
      }
      return std::max(0.0f, sum);
    }
  }
  return 0.0f;
}

std::vector<Bounds3> SparseGrid::occupiedWorldBoxes() const {
  std::vector<Bounds3> boxes;
  if (!trees_) return boxes;
  // Blocks clipped to the active voxels padded by the stencils' reach, as in worldBounds.
  const openvdb::CoordBBox& a = trees_->activeBox;
  const Vec3 clipLo(static_cast<float>(a.min().x()) - 2.0f, static_cast<float>(a.min().y()) - 2.0f,
                    static_cast<float>(a.min().z()) - 2.0f);
  const Vec3 clipHi(static_cast<float>(a.max().x()) + 2.0f, static_cast<float>(a.max().y()) + 2.0f,
                    static_cast<float>(a.max().z()) + 2.0f);
  const float k = static_cast<float>(openvdb::FloatTree::LeafNodeType::DIM);
  for (auto it = trees_->blockMax->cbeginValueOn(); it; ++it) {
    if (!(*it > 0.0f)) continue;
    const openvdb::CoordBBox cells = it.getBoundingBox();
    Vec3 lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = std::max(static_cast<float>(cells.min()[axis]) * k - 0.5f, clipLo[axis]);
      hi[axis] = std::min(static_cast<float>(cells.max()[axis] + 1) * k - 0.5f, clipHi[axis]);
    }
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) continue;
    Bounds3 world;
    for (int c = 0; c < 8; ++c)
      world.extend(
          indexToWorld_.point(Vec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z)));
    boxes.push_back(world);
  }
  return boxes;
}

void SparseGrid::majorantSpans(const Ray& ray, float tmin, float tmax, MajorantLevel level,
                               std::vector<MajorantSpan>& out, uint64_t* cells) const {
  if (!trees_) return;
  auto add = [&out](float t0, float t1, float majorant) {
    if (!(majorant > 0.0f)) return;
    if (!out.empty() && out.back().majorant == majorant && out.back().t1 >= t0 - 1e-6f)
      out.back().t1 = t1;
    else
      out.push_back({t0, t1, majorant});
  };
  uint64_t visited = 0;
  if (level == MajorantLevel::kGlobal) {
    Ray r = ray;
    r.tmin = tmin;
    r.tmax = tmax;
    float t0, t1;
    if (worldBounds_.intersect(r, t0, t1) && t1 > t0) add(t0, t1, maxValue_);
    visited = 1;
  } else {
    const Ray local = toIndexRay(worldToIndex_, ray);
    const bool block = level == MajorantLevel::kBlock;
    const MajorantTree& tree = block ? *trees_->blockMax : *trees_->nodeMax;
    const float size = static_cast<float>(openvdb::FloatTree::LeafNodeType::DIM) *
                       (block ? 1.0f : static_cast<float>(openvdb::FloatTree::LeafNodeType::DIM));
    visited = walkCells(tree, block ? trees_->blockCells : trees_->nodeCells, size, local, tmin,
                        tmax, add);
  }
  if (cells) *cells += visited;
}

void SparseGrid::intervals(const Ray& ray, float tmin, float tmax,
                           std::vector<std::pair<float, float>>& out) const {
  if (!trees_) return;
  const Ray local = toIndexRay(worldToIndex_, ray);
  walkCells(*trees_->blockMax, trees_->blockCells,
            static_cast<float>(openvdb::FloatTree::LeafNodeType::DIM), local, tmin, tmax,
            [&out](float t0, float t1, float value) {
              if (!(value > 0.0f)) return;
              if (!out.empty() && out.back().second >= t0 - 1e-6f)
                out.back().second = t1;
              else
                out.emplace_back(t0, t1);
            });
}

MajorantLevel SparseGrid::cheapestMajorantLevel(float densityScale, Interpolation interp) const {
  if (!trees_) return MajorantLevel::kGlobal;
  // Fixed rays from a sphere around the grid towards points inside it.
  constexpr int kRays = 64;
  const Vec3 centre = worldBounds_.center();
  const Vec3 diagonal = worldBounds_.diagonal();
  const float radius = 0.5f * length(diagonal);
  Rng rng(0x6c766f78, 1);
  double cost[3] = {0.0, 0.0, 0.0};
  std::vector<MajorantSpan> spans;
  for (int i = 0; i < kRays; ++i) {
    const Vec3 from = centre + uniformSphere(rng.uniform(), rng.uniform()) * radius;
    const Vec3 to = worldBounds_.lo + Vec3(rng.uniform() * diagonal.x, rng.uniform() * diagonal.y,
                                           rng.uniform() * diagonal.z);
    Ray ray;
    ray.origin = from;
    ray.dir = normalize(to - from);
    for (int level = 0; level < 3; ++level) {
      spans.clear();
      uint64_t cells = 0;
      majorantSpans(ray, 0.0f, kInf, static_cast<MajorantLevel>(level), spans, &cells);
      double depth = 0.0;
      for (const MajorantSpan& s : spans) depth += static_cast<double>(s.majorant) * (s.t1 - s.t0);
      cost[level] +=
          kCellCost * static_cast<double>(cells) + lookupCost(interp) * densityScale * depth;
    }
  }
  int best = 0;
  for (int level = 1; level < 3; ++level)
    if (cost[level] < cost[best]) best = level;
  return static_cast<MajorantLevel>(best);
}

bool SparseGrid::hasLeafTable() const { return trees_ && trees_->leafTable.has_value(); }

size_t SparseGrid::memoryBytes() const {
  if (!trees_) return 0;
  return trees_->values->memUsage() + trees_->blockMax->memUsage() + trees_->nodeMax->memUsage() +
         trees_->lowerNodes->memoryBytes() +
         (trees_->leafTable ? trees_->leafTable->memoryBytes() : 0);
}

}  // namespace lvox
