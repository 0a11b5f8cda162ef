#pragma once
// A lat-long (equirectangular) environment: the radiance arriving from every direction,
// read by OpenImageIO (any format it reads; values are linear radiance, W/(m^2 sr)), and an
// importance sampler over its texels. +y is up: row 0 is the zenith, the last row the
// nadir; column u = 0.5 looks along -z and u grows towards +x.
#include <string>
#include <vector>

#include "src/core/math.h"

namespace lvox {

class EnvironmentMap {
 public:
  // Reads `path`, times `scale`. Errors name `sceneFile` and `field`.
  EnvironmentMap(const std::string& path, const RGB& scale, const std::string& sceneFile,
                 const std::string& field);
  // From texels directly (rows from the zenith down), for tests.
  EnvironmentMap(int width, int height, std::vector<RGB> texels);

  // Radiance from direction `dir` (unit): the texel it falls in (piecewise constant, as the
  // sampling density is).
  RGB radiance(const Vec3& dir) const { return texels_[texelOf(dir)]; }
  // A direction with probability proportional to the texel's mean radiance times the
  // solid angle it spans (pick a row, then a column, then uniformly inside the texel);
  // `pdf` is per solid angle. Texels of zero radiance are never chosen.
  Vec3 sample(float u1, float u2, float& pdf) const;
  // Solid-angle density with which `sample` picks `dir`.
  float pdf(const Vec3& dir) const;
  bool black() const { return !(total_ > 0.0); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void buildSampler();
  size_t texelOf(const Vec3& dir) const;
  // Density in (u, v) of texel i: its probability times the texel count.
  float uvDensity(size_t i) const;

  int width_ = 0, height_ = 0;
  std::vector<RGB> texels_;
  std::vector<double> weights_;    // per texel: mean radiance x sin(theta) at its centre
  std::vector<double> rowCdf_;     // height + 1 entries, from 0 to 1
  std::vector<double> columnCdf_;  // per row, width + 1 entries, from 0 to 1
  double total_ = 0.0;
};

}  // namespace lvox
