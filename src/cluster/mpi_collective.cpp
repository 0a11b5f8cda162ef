#include "src/cluster/mpi_collective.h"

#include <climits>
#include <numeric>
#include <stdexcept>

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

}  // namespace

MpiCollective::MpiCollective() {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
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
