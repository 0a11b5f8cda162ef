#include "volume/media/blackbody.h"

#include <algorithm>
#include <cmath>

namespace lvox {
namespace {

// Wyman, Sloan and Shirley 2013, "Simple Analytic Approximations to the CIE XYZ Color
// Matching Functions", the multi-lobe fit (wavelength in nm).
double lobe(double lambda, double mu, double below, double above) {
  const double t = (lambda - mu) / (lambda < mu ? below : above);
  return std::exp(-0.5 * t * t);
}
double xBar(double l) {
  return 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
         0.065 * lobe(l, 501.1, 20.4, 26.2);
}
double yBar(double l) {
  return 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
}
double zBar(double l) {
  return 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

}  // namespace

double planck(double lambda, double kelvin) {
  constexpr double h = 6.62607015e-34, c = 2.99792458e8, k = 1.380649e-23;
  if (!(kelvin > 0.0) || !(lambda > 0.0)) return 0.0;
  const double x = h * c / (lambda * k * kelvin);
  if (x > 700.0) return 0.0;  // exp overflows; the radiance is 0 to double precision
  return 2.0 * h * c * c / (std::pow(lambda, 5.0) * std::expm1(x));
}

Vec3 blackbodyXyz(double kelvin) {
  double x = 0.0, y = 0.0, z = 0.0;
  for (double nm = 360.0; nm <= 830.0; nm += 1.0) {
    const double l = planck(nm * 1e-9, kelvin) * 1e-9;  // per nm
    x += l * xBar(nm);
    y += l * yBar(nm);
    z += l * zBar(nm);
  }
  return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

RGB blackbodyChromaticity(double kelvin) {
  const Vec3 xyz = blackbodyXyz(kelvin);
  if (!(xyz.y > 0.0f)) return RGB(0.0f);
  const double X = xyz.x / xyz.y, Y = 1.0, Z = xyz.z / xyz.y;
  // XYZ -> linear sRGB (Rec.709 primaries, D65 white).
  const double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  const double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  const double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  return {static_cast<float>(std::max(0.0, r)), static_cast<float>(std::max(0.0, g)),
          static_cast<float>(std::max(0.0, b))};
}

RGB blackbodyRadiance(double kelvin) {
  if (!(kelvin > 0.0)) return RGB(0.0f);
  const double t2 = kelvin * kelvin;
  return blackbodyChromaticity(kelvin) * static_cast<float>(kStefanBoltzmann * t2 * t2 / kPi);
}

BlackbodyTable::BlackbodyTable(float maxKelvin)
    : maxKelvin_(std::max(maxKelvin, 1.0f)), perKelvin_(1024.0f / std::max(maxKelvin, 1.0f)) {
  values_.resize(1025);
  for (int i = 0; i <= 1024; ++i)
    values_[static_cast<size_t>(i)] =
        blackbodyRadiance(static_cast<double>(maxKelvin_) * i / 1024.0);
}

RGB BlackbodyTable::operator()(float kelvin) const {
  if (!(kelvin > 0.0f)) return RGB(0.0f);
  const float u = std::min(kelvin, maxKelvin_) * perKelvin_;
  const int i = std::min(static_cast<int>(u), 1023);
  const float f = u - static_cast<float>(i);
  return values_[static_cast<size_t>(i)] * (1.0f - f) + values_[static_cast<size_t>(i) + 1] * f;
}

}  // namespace lvox
