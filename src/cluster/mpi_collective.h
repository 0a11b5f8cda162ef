#pragma once
// Collective over MPI_COMM_WORLD (MPI must be initialised first). The shared counter is
// one 64-bit integer in an MPI window on rank 0 that every rank updates with
// MPI_Fetch_and_op under a passive-target lock: no rank has to serve requests.
#include <mpi.h>

#include "src/core/collective.h"

namespace lvox {

class MpiCollective final : public Collective {
 public:
  MpiCollective();
  ~MpiCollective() override;
  MpiCollective(const MpiCollective&) = delete;
  MpiCollective& operator=(const MpiCollective&) = delete;

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void sum(std::span<float> values) override;
  void sum(std::span<double> values) override;
  void sum(std::span<uint64_t> values) override;
  std::vector<std::string> gather(const std::string& bytes, int root) override;
  std::vector<std::string> allgather(const std::string& bytes) override;
  void broadcast(std::string& bytes, int root) override;
  void barrier() override;
  void resetCounter() override;
  uint64_t take(uint64_t n) override;

 private:
  int rank_ = 0, size_ = 1;
  // Largest piece of one MPI byte transfer (counts are ints): 1 GiB, or
  // LVOX_MPI_PIECE_BYTES (tests exercise the chunked paths with small pieces).
  size_t pieceBytes_ = size_t(1) << 30;
  MPI_Win window_ = MPI_WIN_NULL;
  uint64_t* counter_ = nullptr;  // in the window; rank 0's is the shared one
};

}  // namespace lvox
