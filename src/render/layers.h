#pragma once
// AOV layers: what a render can write beside its beauty image, in the same multi-layer EXR
// (`lvox render --layers LIST`). A pixel sampler fills one SampleLayers per camera sample
// when layers are asked for; the film (film.h) averages them like the beauty.
//
// The five radiance layers split each sample by the first thing the camera ray meets, so
// they add up to the beauty exactly:
//   direct      light from the light sources scattered once, at the first surface;
//   indirect    light reaching the first surface after another scattering (pcb's gather,
//               mc's continuation paths);
//   volume      light scattered towards the camera inside the media along the camera ray
//               (every order; emission the media scatter included);
//   emission    emitters seen directly: emissive surfaces and the media's own emission
//               along the camera ray;
//   environment the environment seen directly (through the media).
// Everything behind a medium is seen through it: those layers carry the camera ray's
// transmittance. The guide layers describe the first surface whatever lies in front:
//   albedo      its diffuse reflectance (textured, at the pixel footprint); 0 where the ray
//               escapes;
//   normal      its world-space shading normal (the mean over the pixel, not renormalised);
//   depth       its distance along the camera ray (Z, averaged over the samples that hit a
//               surface) and the fraction of samples that hit one (coverage.Y);
//   variance    (mc only) the variance of each beauty pixel's mean, per channel: s^2 / n.
#include <cstdint>
#include <string>

#include "src/core/math.h"
#include "src/core/names.h"

namespace lvox {

enum class Layer : uint8_t {
  kDirect,
  kIndirect,
  kVolume,
  kEmission,
  kEnvironment,
  kAlbedo,
  kNormal,
  kDepth,
  kVariance,
};
inline constexpr int kLayerCount = 9;

inline constexpr Named<Layer> kLayerNames[] = {
    {Layer::kDirect, "direct"},           {Layer::kIndirect, "indirect"},
    {Layer::kVolume, "volume"},           {Layer::kEmission, "emission"},
    {Layer::kEnvironment, "environment"}, {Layer::kAlbedo, "albedo"},
    {Layer::kNormal, "normal"},           {Layer::kDepth, "depth"},
    {Layer::kVariance, "variance"},
};

inline std::string_view layerName(Layer layer) { return nameOf(layer, kLayerNames); }

// A set of layers, in the fixed order above whatever order it was asked in.
class LayerSet {
 public:
  bool empty() const { return bits_ == 0; }
  bool has(Layer l) const { return (bits_ >> static_cast<int>(l)) & 1u; }
  void add(Layer l) { bits_ |= 1u << static_cast<int>(l); }
  bool operator==(const LayerSet&) const = default;

  // "all" (every layer `mc` may write: variance only when true) or a comma-separated list
  // of names; an unknown name throws InputError naming `field` and the valid names.
  static LayerSet parse(const std::string& list, bool withVariance, const std::string& field);
  // "direct,indirect,...": the names in order ("" for none), as parse reads them.
  std::string toString() const;

 private:
  uint32_t bits_ = 0;
};

// What one camera sample carries besides its radiance. The radiance parts are zero unless
// the sampler set them; `hit` says whether the camera ray met a surface.
struct SampleLayers {
  RGB direct{0.0f}, indirect{0.0f}, volume{0.0f}, emission{0.0f}, environment{0.0f};
  RGB albedo{0.0f};
  Vec3 normal{0.0f, 0.0f, 0.0f};
  float depth = 0.0f;
  bool hit = false;

  RGB radianceSum() const { return direct + indirect + volume + emission + environment; }
};

}  // namespace lvox
