#pragma once
// Blackbody emission for media with a temperature grid (Blender's smoke and fire caches).
//
// Conversion (docs/scene-format.md, "Blackbody emission"): a temperature T in kelvin emits
// the radiance of Planck's law integrated over all wavelengths, L = sigma T^4 / pi in
// W m^-2 sr^-1 (Stefan-Boltzmann), with the colour of Planck's spectrum: its CIE 1931 XYZ
// (Wyman, Sloan and Shirley's 2013 fit of the colour matching functions, within about 1 % of
// the tables) mapped to linear Rec.709/sRGB primaries and scaled to luminance Y = 1.
// Channels that fall below 0 (deep red below about 1,900 K lies outside the sRGB gamut) are
// clamped to 0. So rgb(T) = L(T) x chromaticity(T), and its luminance is L(T).
#include <vector>

#include "src/core/math.h"

namespace lvox {

inline constexpr double kStefanBoltzmann = 5.670374419e-8;  // W m^-2 K^-4

// Spectral radiance of a blackbody, W m^-2 sr^-1 per metre of wavelength.
double planck(double wavelengthMetres, double kelvin);
// CIE 1931 XYZ of Planck's spectrum at `kelvin` (integrated over 360-830 nm).
Vec3 blackbodyXyz(double kelvin);
// Linear sRGB of unit luminance (Y = 1), negative channels clamped to 0.
RGB blackbodyChromaticity(double kelvin);
// sigma T^4 / pi x chromaticity(T), W m^-2 sr^-1.
RGB blackbodyRadiance(double kelvin);

// blackbodyRadiance tabulated on [0, maxKelvin] for the hot path (1024 intervals, linear
// interpolation; values above maxKelvin are clamped to it).
class BlackbodyTable {
 public:
  explicit BlackbodyTable(float maxKelvin);
  RGB operator()(float kelvin) const;
  float maxKelvin() const { return maxKelvin_; }

 private:
  float maxKelvin_, perKelvin_;
  std::vector<RGB> values_;
};

}  // namespace lvox
