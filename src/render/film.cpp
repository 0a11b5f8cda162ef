#include "src/render/film.h"

#include <algorithm>
#include <cmath>

#include "src/core/error.h"

namespace lvox {
namespace {

// Doubles a layer takes per pixel.
// Depth: the distance sum and the hit count; variance: the beauty's sum and sum of squares
// in double (the film's float beauty would cancel in sum x^2 - n mean^2).
int slotsOf(Layer l) { return l == Layer::kDepth ? 2 : l == Layer::kVariance ? 6 : 3; }

const RGB* radiancePart(const SampleLayers& s, Layer l) {
  switch (l) {
    case Layer::kDirect:
      return &s.direct;
    case Layer::kIndirect:
      return &s.indirect;
    case Layer::kVolume:
      return &s.volume;
    case Layer::kEmission:
      return &s.emission;
    case Layer::kEnvironment:
      return &s.environment;
    case Layer::kAlbedo:
      return &s.albedo;
    default:
      return nullptr;
  }
}

bool finite3(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::vector<float> plane(size_t n) { return std::vector<float>(n, 0.0f); }

}  // namespace

LayerSet LayerSet::parse(const std::string& list, bool withVariance, const std::string& field) {
  LayerSet set;
  if (list == "all") {
    for (const Named<Layer>& n : kLayerNames)
      if (n.value != Layer::kVariance || withVariance) set.add(n.value);
    return set;
  }
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    if (name.empty()) throw InputError(field, "", "empty layer name in '" + list + "'");
    set.add(parseNamed(name, kLayerNames, "layer", field, ""));
    begin = end + 1;
  }
  return set;
}

std::string LayerSet::toString() const {
  std::string s;
  for (const Named<Layer>& n : kLayerNames)
    if (has(n.value)) {
      if (!s.empty()) s += ',';
      s += n.name;
    }
  return s;
}

Film::Film(int width, int height, LayerSet layers) : beauty(width, height), layers_(layers) {
  offsets_.fill(-1);
  for (const Named<Layer>& n : kLayerNames)
    if (layers.has(n.value)) {
      offsets_[static_cast<int>(n.value)] = slots_;
      slots_ += slotsOf(n.value);
    }
  sums_.assign(static_cast<size_t>(width) * height * slots_, 0.0);
}

uint64_t Film::layerBytesPerPixel(const LayerSet& layers) {
  uint64_t slots = 0;
  for (const Named<Layer>& n : kLayerNames)
    if (layers.has(n.value)) slots += slotsOf(n.value);
  return slots * sizeof(double);
}

bool Film::finite(const SampleLayers& s) const {
  return isFinite(s.radianceSum()) && isFinite(s.albedo) && finite3(s.normal) &&
         std::isfinite(s.depth);
}

void Film::addSample(PixelLayerSums& sums, const RGB& radiance, const SampleLayers& sample) const {
  auto add3 = [&](int o, float a, float b, float c) {
    sums[o] += a;
    sums[o + 1] += b;
    sums[o + 2] += c;
  };
  for (const Named<Layer>& n : kLayerNames) {
    const int o = offset(n.value);
    if (o < 0) continue;
    if (const RGB* part = radiancePart(sample, n.value)) {
      add3(o, part->x, part->y, part->z);
    } else if (n.value == Layer::kNormal) {
      add3(o, sample.normal.x, sample.normal.y, sample.normal.z);
    } else if (n.value == Layer::kDepth) {
      if (sample.hit) {
        sums[o] += sample.depth;
        sums[o + 1] += 1.0;
      }
    } else {  // variance: the beauty's sum and sum of squares
      add3(o, radiance.x, radiance.y, radiance.z);
      for (int c = 0; c < 3; ++c)
        sums[o + 3 + c] += static_cast<double>(radiance[c]) * static_cast<double>(radiance[c]);
    }
  }
}

void Film::addPixel(int x, int y, const PixelLayerSums& sums) {
  double* p = sums_.data() + (static_cast<size_t>(y) * beauty.width + x) * slots_;
  for (int i = 0; i < slots_; ++i) p[i] += sums[i];
}

double Film::samplesOf(size_t pixel, int samples) const {
  return std::max(1.0, static_cast<double>(samples) + (extra_.empty() ? 0.0 : extra_[pixel]));
}

uint64_t Film::extraSamples() const {
  uint64_t total = 0;
  for (uint32_t e : extra_) total += e;
  return total;
}

Image Film::beautyMean(int samples) const {
  Image out = beauty;
  for (size_t i = 0; i < out.pixels.size(); ++i)
    out.pixels[i] /= static_cast<float>(samplesOf(i, samples));
  return out;
}

std::vector<ExtraChannel> Film::layerChannels(int samples) const {
  std::vector<ExtraChannel> out;
  const size_t n = beauty.pixels.size();
  const char* rgb[3] = {"R", "G", "B"};
  const char* xyz[3] = {"X", "Y", "Z"};
  for (const Named<Layer>& l : kLayerNames) {
    const int o = offset(l.value);
    if (o < 0) continue;
    const std::string layer(l.name);
    if (l.value == Layer::kDepth) {
      ExtraChannel depth{layer + ".Z", plane(n)}, coverage{"coverage.Y", plane(n)};
      for (size_t i = 0; i < n; ++i) {
        const double count = samplesOf(i, samples);
        const double hits = sums_[i * slots_ + o + 1];
        depth.values[i] = hits > 0 ? static_cast<float>(sums_[i * slots_ + o] / hits) : 0.0f;
        coverage.values[i] = static_cast<float>(hits / count);
      }
      out.push_back(std::move(depth));
      out.push_back(std::move(coverage));
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      ExtraChannel ch{layer + "." + (l.value == Layer::kNormal ? xyz[c] : rgb[c]), plane(n)};
      for (size_t i = 0; i < n; ++i) {
        const double count = samplesOf(i, samples);
        const double sum = sums_[i * slots_ + o + c];
        if (l.value != Layer::kVariance) {
          ch.values[i] = static_cast<float>(sum / count);
          continue;
        }
        // s^2 / n with s^2 = (sum x^2 - n mean^2) / (n - 1); 0 with a single sample.
        const double mean = sum / count;
        const double squares = sums_[i * slots_ + o + 3 + c];
        const double s2 = count > 1.0 ? (squares - count * mean * mean) / (count - 1.0) : 0.0;
        ch.values[i] = static_cast<float>(std::max(0.0, s2) / count);
      }
      out.push_back(std::move(ch));
    }
  }
  return out;
}

}  // namespace lvox
