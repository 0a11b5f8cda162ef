#include "src/world/environment_map.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>

#include "src/core/error.h"

namespace lvox {
namespace {

size_t pick(const double* cdf, size_t n, double u, double& fraction) {
  // The cell whose [cdf[i], cdf[i+1]) holds u, skipping empty cells.
  const size_t i =
      std::min<size_t>(static_cast<size_t>(std::upper_bound(cdf, cdf + n + 1, u) - cdf), n) - 1;
  const double width = cdf[i + 1] - cdf[i];
  fraction = width > 0.0 ? std::clamp((u - cdf[i]) / width, 0.0, 1.0 - 1e-7) : 0.5;
  return i;
}

}  // namespace

EnvironmentMap::EnvironmentMap(const std::string& path, const RGB& scale,
                               const std::string& sceneFile, const std::string& field) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string msg = OIIO::geterror();
    msg = msg.substr(0, msg.find('\n'));
    throw InputError(sceneFile, field, "cannot read environment map '" + path + "': " + msg);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 2 || spec.height < 1 || spec.width > 1 << 15 || spec.height > 1 << 14)
    throw InputError(sceneFile, field, "environment map '" + path + "' must be 2x1 to 32768x16384");
  const int channels = spec.nchannels;
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw InputError(sceneFile, field, "cannot read environment map '" + path + "'");
  width_ = spec.width;
  height_ = spec.height;
  texels_.resize(static_cast<size_t>(width_) * height_);
  for (size_t i = 0; i < texels_.size(); ++i) {
    const float* p = &pixels[i * static_cast<size_t>(channels)];
    const RGB c = channels >= 3 ? RGB(p[0], p[1], p[2]) : RGB(p[0]);
    if (!isFinite(c) || std::min({c.x, c.y, c.z}) < 0.0f || maxComponent(c) > 1e9f)
      throw InputError(sceneFile, field,
                       "environment map '" + path + "' has a texel outside [0, 1e9]");
    texels_[i] = c * scale;
  }
  buildSampler();
}

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<RGB> texels)
    : width_(width), height_(height), texels_(std::move(texels)) {
  buildSampler();
}

void EnvironmentMap::buildSampler() {
  const size_t w = static_cast<size_t>(width_), h = static_cast<size_t>(height_);
  weights_.assign(w * h, 0.0);
  rowCdf_.assign(h + 1, 0.0);
  columnCdf_.assign(h * (w + 1), 0.0);
  for (size_t y = 0; y < h; ++y) {
    const double sinTheta = std::sin(kPi * (static_cast<double>(y) + 0.5) / static_cast<double>(h));
    double* cdf = &columnCdf_[y * (w + 1)];
    for (size_t x = 0; x < w; ++x) {
      weights_[y * w + x] = average(texels_[y * w + x]) * sinTheta;
      cdf[x + 1] = cdf[x] + weights_[y * w + x];
    }
    rowCdf_[y + 1] = rowCdf_[y] + cdf[w];
    if (cdf[w] > 0.0)
      for (size_t x = 1; x <= w; ++x) cdf[x] /= cdf[w];
  }
  total_ = rowCdf_[h];
  if (total_ > 0.0)
    for (double& c : rowCdf_) c /= total_;
}

size_t EnvironmentMap::texelOf(const Vec3& dir) const {
  const float u = 0.5f + std::atan2(dir.x, -dir.z) / (2.0f * kPi);
  const float v = std::acos(std::clamp(dir.y, -1.0f, 1.0f)) / kPi;
  const int x = std::clamp(static_cast<int>(u * static_cast<float>(width_)), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(v * static_cast<float>(height_)), 0, height_ - 1);
  return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
}

float EnvironmentMap::uvDensity(size_t i) const {
  return static_cast<float>(weights_[i] / total_ * static_cast<double>(width_) * height_);
}

Vec3 EnvironmentMap::sample(float u1, float u2, float& pdf) const {
  const size_t w = static_cast<size_t>(width_), h = static_cast<size_t>(height_);
  double fy, fx;
  const size_t y = pick(rowCdf_.data(), h, u1, fy);
  const size_t x = pick(&columnCdf_[y * (w + 1)], w, u2, fx);
  const double u = (static_cast<double>(x) + fx) / static_cast<double>(w);
  const double v = (static_cast<double>(y) + fy) / static_cast<double>(h);
  const double theta = kPi * v, phi = 2.0 * kPi * (u - 0.5);
  const double sinTheta = std::sin(theta);
  const Vec3 dir(static_cast<float>(sinTheta * std::sin(phi)), static_cast<float>(std::cos(theta)),
                 static_cast<float>(-sinTheta * std::cos(phi)));
  // d omega = 2 pi^2 sin(theta) du dv.
  pdf =
      sinTheta > 0.0 ? uvDensity(y * w + x) / static_cast<float>(2.0 * kPi * kPi * sinTheta) : 0.0f;
  return dir;
}

float EnvironmentMap::pdf(const Vec3& dir) const {
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - dir.y * dir.y));
  if (!(sinTheta > 0.0f) || black()) return 0.0f;
  return uvDensity(texelOf(dir)) / (2.0f * kPi * kPi * sinTheta);
}

}  // namespace lvox
