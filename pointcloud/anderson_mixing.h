#pragma once
// Anderson acceleration of a fixed-point iteration x = G(x) (Anderson 1965; the form of
// Walker & Ni 2011, "Anderson acceleration for fixed-point iterations", with the damping
// of 1): each step takes the combination of the last few evaluations G(x_j) whose
// residuals f_j = G(x_j) - x_j combine to the least squares residual.
//
// The interreflection's passes are such an iteration, with G(x) = b + W x (the cloud's
// direct light and one gather of its light), and plain passes converge by the spectral
// radius of W per pass: 0.9 in a closed room of white smoke, so the rest shrinks tenfold
// every 22 passes. For a linear G, Anderson with depth m is a restarted Krylov method
// (GMRES(m) up to the order of operations): it kills the slowest modes first instead of
// last (docs/pcb.md, "How many passes").
//
// A mix is one sweep over the vectors plus one for the new iterate: the Gram matrix of
// the differences is kept, only the newest column's products are new. Dot products run
// over fixed blocks of the vector and sum in block order, so a mix gives the same result
// whatever the number of threads.
#include <cstddef>
#include <span>
#include <vector>

namespace lvox {

class AndersonMixing {
 public:
  // `depth`: how many past differences take part (1 or more).
  AndersonMixing(size_t size, int depth);

  // `x` holds x_k on entry and x_{k+1} on return; `g` is G(x_k). The first call (no
  // history yet) returns x_{k+1} = g: a plain pass.
  void mix(std::span<float> x, std::span<const float> g);
  // The differences that took part in the last mix (0 after the first call).
  int used() const { return used_; }

  // The memory a mixer of that size and depth holds.
  static size_t bytesFor(size_t size, int depth);

 private:
  size_t size_;
  int depth_;
  std::vector<float> previousF_, previousG_;
  std::vector<std::vector<float>> deltaF_, deltaG_;  // a ring of `depth` columns each
  std::vector<double> gram_;                         // <dF_i, dF_j> by slot, depth x depth
  int stored_ = 0, newest_ = -1;
  bool havePrevious_ = false;
  int used_ = 0;
};

}  // namespace lvox
