#pragma once
// The processes of one run that is split over several (MPI ranks under mpirun or srun), as
// the libraries see them: who am I, how many are we, sum these numbers over all of us,
// share these bytes, hand out work from one shared counter. The libraries call it only between
// phases, per interreflection pass and per band of tiles, never per sample. They do not know MPI:
// the app gives them src/cluster's MPI implementation when it was started by an MPI launcher, else
// SingleProcess, under which every call is trivial and the render is the ordinary one-process
// render.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/core/math.h"

namespace lvox {

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  bool isRoot() const { return rank() == 0; }
  bool distributed() const { return size() > 1; }

  // Collective: every rank passes the same number of values, and on return each holds the
  // element-wise sum over the ranks (MPI_Allreduce).
  virtual void sum(std::span<float> values) = 0;
  virtual void sum(std::span<double> values) = 0;
  virtual void sum(std::span<uint64_t> values) = 0;
  // Collective: at `root`, every rank's bytes in rank order; elsewhere an empty vector.
  virtual std::vector<std::string> gather(const std::string& bytes, int root) = 0;
  // Collective: every rank passes its own bytes (any length, 0 included); on return every
  // rank holds all of them in rank order (MPI_Allgatherv; past 2 GiB in all, one chunked
  // broadcast per rank). For data built in parallel across the ranks, then shared.
  virtual std::vector<std::string> allgather(const std::string& bytes) = 0;
  // Collective: on return every rank's `bytes` are root's (MPI_Bcast, chunked past 2 GiB).
  virtual void broadcast(std::string& bytes, int root) = 0;
  // Collective: waits until every rank has arrived.
  virtual void barrier() = 0;

  // A counter shared by every rank for dynamic load balancing. resetCounter is collective
  // and sets it to 0; take(n) atomically adds n and returns the value before (so ranks
  // that call it concurrently get disjoint ranges [value, value + n)).
  virtual void resetCounter() = 0;
  virtual uint64_t take(uint64_t n) = 0;
};

// One process: rank 0 of 1.
class SingleProcess final : public Collective {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void sum(std::span<float>) override {}
  void sum(std::span<double>) override {}
  void sum(std::span<uint64_t>) override {}
  std::vector<std::string> gather(const std::string& bytes, int) override { return {bytes}; }
  std::vector<std::string> allgather(const std::string& bytes) override { return {bytes}; }
  void broadcast(std::string&, int) override {}
  void barrier() override {}
  void resetCounter() override { counter_ = 0; }
  uint64_t take(uint64_t n) override {
    const uint64_t before = counter_;
    counter_ += n;
    return before;
  }

 private:
  uint64_t counter_ = 0;
};

// The shared instance for code that runs in one process.
inline Collective& singleProcess() {
  static SingleProcess instance;
  return instance;
}

// RGB values as the floats a collective sums.
inline std::span<float> floatsOf(std::vector<RGB>& values) {
  static_assert(sizeof(RGB) == 3 * sizeof(float), "RGB must be three packed floats");
  return {reinterpret_cast<float*>(values.data()), 3 * values.size()};
}

}  // namespace lvox
