#include "src/cluster/mpi_collective.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>

namespace lvox {
namespace {

// MPI counts are ints: long spans go in pieces.
template <class T>
void allreduceSum(std::span<T> values, MPI_Datatype type) {
  constexpr size_t kPiece = size_t(1) << 28;
  for (size_t begin = 0; begin < values.size(); begin += kPiece) {
    const size_t count = std::min(kPiece, values.size() - begin);
    MPI_Allreduce(MPI_IN_PLACE, values.data() + begin, static_cast<int>(count), type, MPI_SUM,
                  MPI_COMM_WORLD);
  }
}

// Root's `count` bytes at `data` to every rank, in pieces of at most `piece` bytes.
void broadcastBytes(char* data, size_t count, int root, size_t piece) {
  for (size_t begin = 0; begin < count; begin += piece)
    MPI_Bcast(data + begin, static_cast<int>(std::min(piece, count - begin)), MPI_BYTE, root,
              MPI_COMM_WORLD);
}

}  // namespace

MpiCollective::MpiCollective() {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (const char* piece = std::getenv("LVOX_MPI_PIECE_BYTES")) {
    const long long bytes = std::atoll(piece);
    if (bytes > 0 && bytes <= INT_MAX) pieceBytes_ = static_cast<size_t>(bytes);
  }
  const MPI_Aint bytes = rank_ == 0 ? static_cast<MPI_Aint>(sizeof(uint64_t)) : 0;
  MPI_Win_allocate(bytes, sizeof(uint64_t), MPI_INFO_NULL, MPI_COMM_WORLD, &counter_, &window_);
  if (rank_ == 0) *counter_ = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Win_lock_all(0, window_);
}

MpiCollective::~MpiCollective() {
  MPI_Win_unlock_all(window_);
  MPI_Win_free(&window_);
}

void MpiCollective::sum(std::span<float> values) { allreduceSum(values, MPI_FLOAT); }
void MpiCollective::sum(std::span<double> values) { allreduceSum(values, MPI_DOUBLE); }
void MpiCollective::sum(std::span<uint64_t> values) { allreduceSum(values, MPI_UINT64_T); }

std::vector<std::string> MpiCollective::gather(const std::string& bytes, int root) {
  if (bytes.size() > static_cast<size_t>(INT_MAX))
    throw std::runtime_error("MPI gather: more than 2 GB from one rank");
  const int length = static_cast<int>(bytes.size());
  std::vector<int> lengths(rank_ == root ? size_ : 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, root, MPI_COMM_WORLD);
  std::vector<int> offsets(lengths.size(), 0);
  if (!lengths.empty()) std::exclusive_scan(lengths.begin(), lengths.end(), offsets.begin(), 0);
  std::string all(rank_ == root ? static_cast<size_t>(offsets.back() + lengths.back()) : 0, '\0');
  MPI_Gatherv(bytes.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
              root, MPI_COMM_WORLD);
  std::vector<std::string> out;
  for (size_t r = 0; r < lengths.size(); ++r)
    out.push_back(all.substr(static_cast<size_t>(offsets[r]), static_cast<size_t>(lengths[r])));
  return out;
}

std::vector<std::string> MpiCollective::allgather(const std::string& bytes) {
  const uint64_t mine = bytes.size();
  std::vector<uint64_t> lengths(static_cast<size_t>(size_));
  MPI_Allgather(&mine, 1, MPI_UINT64_T, lengths.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  const uint64_t total = std::accumulate(lengths.begin(), lengths.end(), uint64_t(0));
  std::vector<std::string> out(lengths.size());
  if (total <= pieceBytes_) {
    // One MPI_Allgatherv: its counts and offsets fit in ints.
    std::vector<int> counts(lengths.size()), offsets(lengths.size(), 0);
    for (size_t r = 0; r < lengths.size(); ++r) counts[r] = static_cast<int>(lengths[r]);
    std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
    std::string all(static_cast<size_t>(total), '\0');
    MPI_Allgatherv(bytes.data(), static_cast<int>(mine), MPI_BYTE, all.data(), counts.data(),
                   offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
    for (size_t r = 0; r < lengths.size(); ++r)
      out[r] = all.substr(static_cast<size_t>(offsets[r]), static_cast<size_t>(counts[r]));
    return out;
  }
  // Past one piece: each rank's bytes broadcast from it in pieces (the same bytes moved).
  for (size_t r = 0; r < lengths.size(); ++r) {
    if (static_cast<int>(r) == rank_)
      out[r] = bytes;
    else
      out[r].assign(static_cast<size_t>(lengths[r]), '\0');
    broadcastBytes(out[r].data(), out[r].size(), static_cast<int>(r), pieceBytes_);
  }
  return out;
}

void MpiCollective::broadcast(std::string& bytes, int root) {
  uint64_t length = bytes.size();
  MPI_Bcast(&length, 1, MPI_UINT64_T, root, MPI_COMM_WORLD);
  if (rank_ != root) bytes.assign(static_cast<size_t>(length), '\0');
  broadcastBytes(bytes.data(), bytes.size(), root, pieceBytes_);
}

void MpiCollective::barrier() { MPI_Barrier(MPI_COMM_WORLD); }

void MpiCollective::resetCounter() {
  // Everyone has stopped taking from the last round before rank 0 zeroes the counter,
  // and nobody takes from the next before it is zero.
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank_ == 0) {
    const uint64_t zero = 0;
    uint64_t before = 0;
    MPI_Fetch_and_op(&zero, &before, MPI_UINT64_T, 0, 0, MPI_REPLACE, window_);
    MPI_Win_flush(0, window_);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

uint64_t MpiCollective::take(uint64_t n) {
  uint64_t before = 0;
  MPI_Fetch_and_op(&n, &before, MPI_UINT64_T, 0, 0, MPI_SUM, window_);
  MPI_Win_flush(0, window_);
  return before;
}

}  // namespace lvox
