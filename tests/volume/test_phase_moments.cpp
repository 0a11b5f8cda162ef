#include <gtest/gtest.h>

#include <cmath>

#include "sphere_quadrature.h"
#include "src/core/spherical_harmonics.h"
#include "volume/phase.h"

namespace lvox {
namespace {

// Funk-Hecke: the projection of a phase function around the axis u is its Legendre
// moment times the basis at u, band by band: mean of p(w . u) Yhat_k(w) = chi_l Yhat_k(u)
// / (4 pi). This is what lets an lvoxel scatter its incident harmonics with its phase.
TEST(SphericalHarmonics, PhaseConvolutionScalesEachBandByItsMoment) {
  const Vec3 u = normalize(Vec3(0.3f, -0.5f, 0.8f));
  float yu[kShCoefficients];
  shBasis(u, kShCoefficients, yu);
  for (const PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::Schlick}) {
    const PhaseFunction p = PhaseFunction::make(kind, 0.6f);
    for (int k = 0; k < kShCoefficients; ++k) {
      const double m = test::sphereMean(
          [&](const Vec3& w) {
            float y[kShCoefficients];
            shBasis(w, kShCoefficients, y);
            return static_cast<double>(p.eval(dot(w, u))) * y[k];
          },
          4000, 800);
      const double expected = p.moment(shBand(k)) * yu[k] / (4.0 * M_PI);
      EXPECT_NEAR(m, expected, 2e-4) << static_cast<int>(kind) << " " << k;
    }
  }
}

// Henyey-Greenstein's moments are g^l; Schlick's come from quadrature and its first is
// its mean cosine. delta-M: the forward peak is chi_3 and the rest's moments are
// (chi_l - f) / (1 - f); an isotropic phase has no peak.
TEST(PhaseMoments, HenyeyGreensteinSchlickAndTheirForwardPeaks) {
  const PhaseFunction hg = PhaseFunction::make(PhaseKind::HenyeyGreenstein, 0.8f);
  for (int l = 0; l <= 4; ++l) EXPECT_NEAR(hg.moment(l), std::pow(0.8, l), 1e-6) << l;
  const PhaseFunction::Truncated t = hg.truncated(3);
  EXPECT_NEAR(t.forward, 0.512f, 1e-6f);
  EXPECT_NEAR(t.moment[1], (0.8f - 0.512f) / 0.488f, 1e-5f);
  EXPECT_NEAR(t.moment[2], (0.64f - 0.512f) / 0.488f, 1e-5f);
  // The rest's three-band expansion (mean 1) dips to -0.054 at mu = -0.45, where HG's own
  // reaches -0.6 at mu = 0.
  auto series = [](float m1, float m2, float mu) {
    return 1.0f + 3.0f * m1 * mu + 5.0f * m2 * 0.5f * (3.0f * mu * mu - 1.0f);
  };
  EXPECT_NEAR(series(hg.moment(1), hg.moment(2), 0.0f), -0.6f, 1e-5f);
  for (float mu = -1.0f; mu <= 1.0f; mu += 0.01f)
    EXPECT_GT(series(t.moment[1], t.moment[2], mu), -0.055f) << mu;

  const PhaseFunction schlick = PhaseFunction::make(PhaseKind::Schlick, 0.5f);
  double meanCos = 0.0;  // independent quadrature of the mean cosine
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + (i + 0.5) * 2.0 / n;
    meanCos += schlick.eval(static_cast<float>(mu)) * mu * 2.0 / n * 2.0 * M_PI;
  }
  EXPECT_NEAR(schlick.moment(1), meanCos, 1e-4);
  EXPECT_GT(schlick.moment(2), 0.0f);
  EXPECT_LT(schlick.moment(2), schlick.moment(1));

  const PhaseFunction iso = PhaseFunction::make(PhaseKind::Isotropic, 0.0f);
  EXPECT_EQ(iso.truncated(3).forward, 0.0f);
  EXPECT_EQ(iso.truncated(3).moment[1], 0.0f);
  EXPECT_EQ(iso.moment(0), 1.0f);
}

}  // namespace
}  // namespace lvox
