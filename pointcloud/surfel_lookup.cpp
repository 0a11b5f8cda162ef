#include "pointcloud/surfel_lookup.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace lvox {

uint64_t SurfelLookup::blockKey(long x, long y, long z) {
  // 21 bits per axis (offset to keep them non-negative): about 2 million blocks per axis.
  // >> 2 is floor division by 4 for negative cells too.
  const auto u = [](long v) { return static_cast<uint64_t>((v >> 2) + (1L << 20)) & 0x1fffffull; };
  return (u(x) << 42) | (u(y) << 21) | u(z);
}

unsigned SurfelLookup::cellBit(long x, long y, long z) {
  // & 3 is the cell's place along an axis, negative cells too (two's complement).
  return static_cast<unsigned>((x & 3) | (y & 3) << 2 | (z & 3) << 4);
}

long SurfelLookup::cellOf(float v) const { return static_cast<long>(std::floor(v / cell_)); }

SurfelLookup::SurfelLookup(const CloudSurfels& surfels, float cell)
    : surfels_(&surfels), cell_(cell > 0.0f ? cell : 1.0f) {
  const size_t n = surfels.size();
  // Sorting by (block, place in the block) stores each block's cells one after another,
  // in the order of their mask bits.
  std::vector<uint64_t> block(n);
  std::vector<uint8_t> bit(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = surfels.position(i);
    const long x = cellOf(p.x), y = cellOf(p.y), z = cellOf(p.z);
    block[i] = blockKey(x, y, z);
    bit[i] = static_cast<uint8_t>(cellBit(x, y, z));
  }
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  // By cell, and by index within a cell (the search's tie-breaking order).
  std::sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) {
    if (block[a] != block[b]) return block[a] < block[b];
    return bit[a] != bit[b] ? bit[a] < bit[b] : a < b;
  });
  std::vector<Block> occupied;
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = order_[k];
    const bool newBlock = occupied.empty() || occupied.back().key != block[i];
    if (newBlock) occupied.push_back(Block{block[i], 0, static_cast<uint32_t>(cellBegin_.size())});
    const uint64_t mask = 1ull << bit[i];
    if (!(occupied.back().occupied & mask)) {
      occupied.back().occupied |= mask;
      cellBegin_.push_back(static_cast<uint32_t>(k));
    }
  }
  cellBegin_.push_back(static_cast<uint32_t>(n));
  cellBegin_.shrink_to_fit();
  // At most half full: short probe sequences.
  size_t capacity = 2;
  while (capacity < 2 * occupied.size()) capacity *= 2;
  blocks_.assign(capacity, Block{});
  for (const Block& b : occupied) {
    size_t slot = slotOf(b.key, capacity - 1);
    while (blocks_[slot].key != kEmptyKey) slot = (slot + 1) & (capacity - 1);
    blocks_[slot] = b;
  }
}

size_t SurfelLookup::slotOf(uint64_t key, size_t mask) {
  // A 64-bit mix (splitmix64's finaliser): neighbouring blocks land far apart.
  key ^= key >> 30;
  key *= 0xbf58476d1ce4e5b9ull;
  key ^= key >> 27;
  key *= 0x94d049bb133111ebull;
  key ^= key >> 31;
  return static_cast<size_t>(key) & mask;
}

const SurfelLookup::Block* SurfelLookup::findBlock(uint64_t key) const {
  const size_t mask = blocks_.size() - 1;
  for (size_t slot = slotOf(key, mask);; slot = (slot + 1) & mask) {
    const Block& b = blocks_[slot];
    if (b.key == key) return &b;
    if (b.key == kEmptyKey) return nullptr;
  }
}

size_t SurfelLookup::memoryBytes() const {
  return order_.capacity() * sizeof(uint32_t) + cellBegin_.capacity() * sizeof(uint32_t) +
         blocks_.capacity() * sizeof(Block);
}

namespace {

// The 27 cells around a point's cell, for a point nearer the lower face of its cell on
// every axis (a query mirrors the axes where it is not). First the 8 cells of that
// corner, which hold every surfel within half a cell of the point, then the 19 others;
// each part nearest class first (itself, sharing a face, an edge, a corner). The first
// candidates found are likely the best, and the 19 are mostly passed over at once.
struct CellOffset {
  int8_t dx, dy, dz;
};
constexpr size_t kCornerCells = 8;
constexpr std::array<CellOffset, 27> kCellsNearestFirst = [] {
  std::array<CellOffset, 27> out{};
  int k = 0;
  for (int far = 0; far <= 1; ++far)             // in the near corner, then not
    for (int shared = 0; shared <= 3; ++shared)  // how many axes differ from the centre cell
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            if ((dx != 0) + (dy != 0) + (dz != 0) == shared &&
                (dx > 0 || dy > 0 || dz > 0) == (far == 1))
              out[static_cast<size_t>(k++)] = {static_cast<int8_t>(dx), static_cast<int8_t>(dy),
                                               static_cast<int8_t>(dz)};
  return out;
}();

}  // namespace

long SurfelLookup::nearest(const Vec3& p, const Vec3& n) const {
  if (!surfels_ || blocks_.empty()) return -1;
  const CloudSurfels& s = *surfels_;
  const long cx = cellOf(p.x), cy = cellOf(p.y), cz = cellOf(p.z);
  // Squared distances from p to the lower and upper face of its cell along each axis: a
  // neighbouring cell's surfels lie at least that far along it.
  const Vec3 lo(p.x - static_cast<float>(cx) * cell_, p.y - static_cast<float>(cy) * cell_,
                p.z - static_cast<float>(cz) * cell_);
  const Vec3 hi = Vec3(cell_) - lo;
  // Less a margin: the cells are binned by floor(v / cell), rounded unlike lo and hi.
  const float margin = 1e-4f * cell_;
  auto gap2 = [margin](float g) { return g > margin ? (g - margin) * (g - margin) : 0.0f; };
  // gaps[axis][d + 1]: the bound's term for a neighbour at offset d along the axis.
  const float gaps[3][3] = {{gap2(lo.x), 0.0f, gap2(hi.x)},
                            {gap2(lo.y), 0.0f, gap2(hi.y)},
                            {gap2(lo.z), 0.0f, gap2(hi.z)}};
  // The table's offsets mirrored along the axes where the point is nearer the upper face.
  const int mx = hi.x < lo.x ? -1 : 1, my = hi.y < lo.y ? -1 : 1, mz = hi.z < lo.z ? -1 : 1;
  // No cell after the corner's lies nearer than the nearest of the three far faces.
  const float beyondCorner = std::min({gaps[0][1 + mx], gaps[1][1 + my], gaps[2][1 + mz]});
  NearestSurfelChoice choice(s, p, n);
  // The blocks met so far, by their offset from the point's block (-1, 0 or 1 per axis):
  // the corner's 8 cells lie in 1 to 8 blocks, each looked up once.
  std::array<const Block*, 27> blocks;
  uint32_t fetched = 0;  // bit m: blocks[m] is set
  for (size_t j = 0; j < kCellsNearestFirst.size(); ++j) {
    if (j == kCornerCells && !choice.couldImprove(beyondCorner)) break;
    const int dx = kCellsNearestFirst[j].dx * mx, dy = kCellsNearestFirst[j].dy * my,
              dz = kCellsNearestFirst[j].dz * mz;
    const float bound = gaps[0][dx + 1] + gaps[1][dy + 1] + gaps[2][dz + 1];
    if (!choice.couldImprove(bound)) continue;
    const long x = cx + dx, y = cy + dy, z = cz + dz;
    const int m = static_cast<int>(((x >> 2) - (cx >> 2)) + 3 * ((y >> 2) - (cy >> 2)) +
                                   9 * ((z >> 2) - (cz >> 2)) + 13);
    if (!((fetched >> m) & 1u)) {
      blocks[static_cast<size_t>(m)] = findBlock(blockKey(x, y, z));
      fetched |= 1u << m;
    }
    const Block* block = blocks[static_cast<size_t>(m)];
    if (!block) continue;
    const unsigned b = cellBit(x, y, z);
    if (!((block->occupied >> b) & 1u)) continue;
    const uint32_t c = block->firstCell +
                       static_cast<uint32_t>(std::popcount(block->occupied & ((1ull << b) - 1)));
    for (uint32_t k = cellBegin_[c]; k < cellBegin_[c + 1]; ++k) choice.consider(order_[k]);
  }
  // Blocks 2^21 apart share keys: a candidate from such a block is not near (the reach).
  return choice.result(cell_);
}

}  // namespace lvox
