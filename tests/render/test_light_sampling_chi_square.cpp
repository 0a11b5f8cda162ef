// Chi-square goodness-of-fit tests of the light set's sampling (src/render/light_set.h):
// the directions of area-light samples against the solid-angle pdf the light set claims
// (areaPdf, found here by casting rays at the emitters), and the environment's cosine and
// uniform samples against cos/pi and 1/(4 pi). Method: tests/chi_square.h.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "chi_square.h"
#include "square_lamp.h"
#include "src/render/light_set.h"
#include "src/world/mesh_loader.h"

namespace lvox {
namespace {

constexpr int kSamples = 1000000;  // about 1250 per cell of 20 x 40
constexpr double kPi = std::numbers::pi;

struct V {
  double x, y, z;
};
V sub(V a, V b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V crossV(V a, V b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dotV(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V toV(const Vec3& v) { return {v.x, v.y, v.z}; }

// Distance along the ray o + t d to triangle abc (Moller-Trumbore, in double), if hit.
std::optional<double> hit(V o, V d, V a, V b, V c) {
  const V e1 = sub(b, a), e2 = sub(c, a), p = crossV(d, e2);
  const double det = dotV(e1, p);
  if (std::abs(det) < 1e-14) return std::nullopt;
  const V s = sub(o, a);
  const double u = dotV(s, p) / det;
  const V q = crossV(s, e1);
  const double v = dotV(d, q) / det;
  const double t = dotV(e2, q) / det;
  if (u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 0.0) return std::nullopt;
  return t;
}

// Two emitters of different size and radiance, one facing the point and one tilted off to
// the side, so the pick by area and the conversion to solid angle are both exercised.
World emitterWorld() {
  World scene = test::squareLampWorld(1.0f);
  scene.materials.push_back(Material{"lamp2", RGB(0.0f), RGB(2.0f)});
  addTriangle(scene.mesh, Vec3(1.5f, -0.5f, -0.3f), Vec3(2.0f, 0.8f, 0.4f), Vec3(1.2f, 0.9f, -0.6f),
              1);
  return scene;
}

V unitV(V v) {
  const double l = std::sqrt(dotV(v, v));
  return {v.x / l, v.y / l, v.z / l};
}

// The solid angle of triangle abc seen from o, by l'Huilier's theorem (not the light
// set's formula): tan(E/4)^2 = tan(s/2) tan((s-a)/2) tan((s-b)/2) tan((s-c)/2) over the
// sides a, b, c of the spherical triangle and their half sum s.
double solidAngle(V o, V a, V b, V c) {
  const V u = unitV(sub(a, o)), v = unitV(sub(b, o)), w = unitV(sub(c, o));
  const double sa = std::acos(dotV(v, w)), sb = std::acos(dotV(w, u)), sc = std::acos(dotV(u, v));
  const double half = 0.5 * (sa + sb + sc);
  const double t = std::tan(0.5 * half) * std::tan(0.5 * (half - sa)) *
                   std::tan(0.5 * (half - sb)) * std::tan(0.5 * (half - sc));
  return 4.0 * std::atan(std::sqrt(std::max(0.0, t)));
}

// The solid-angle pdf LightSet::sampleArea claims for direction d seen from o: the sum
// over the emitters the ray crosses of the triangle's share of the area times its own
// pdf: 1 / its solid angle where it is sampled by solid angle, else its area pdf
// d^2 / (|cos| area).
double areaPdf(const World& scene, const LightSet& lights, V o, V d) {
  double pdf = 0.0;
  const TriangleMesh& mesh = scene.mesh;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const V a = toV(mesh.vertex(t, 0)), b = toV(mesh.vertex(t, 1)), c = toV(mesh.vertex(t, 2));
    if (const auto dist = hit(o, d, a, b, c)) {
      const V n = crossV(sub(b, a), sub(c, a));
      const double area = 0.5 * std::sqrt(dotV(n, n));
      const double cosLight = std::abs(dotV(n, d)) / std::sqrt(dotV(n, n));
      const double share = area / lights.emissiveArea();
      const double omega = solidAngle(o, a, b, c);
      pdf +=
          omega >= LightSet::kMinSphericalSolidAngle && omega <= LightSet::kMaxSphericalSolidAngle
              ? share / omega
              : share * *dist * *dist / (cosLight * area);
    }
  }
  return pdf;
}

V direction(double cosTheta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
  return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

TEST(LightSamplingChiSquare, AreaLights) {
  const World scene = emitterWorld();
  const LightSet lights(scene, 1);
  const Vec3 p(0.2f, 0.1f, 0.0f);
  Rng rng(20, 0);
  test::SphereHistogram h(20, 40);
  int pdfMismatches = 0, radianceMismatches = 0;
  for (int i = 0; i < kSamples; ++i) {
    const LightSample s = lights.sampleArea(p, rng);
    ASSERT_TRUE(s.fromEmitter);
    h.add(s.wi.x, s.wi.y, s.wi.z);
    // The pdf the sample carries is the one of its direction (for MIS), and its radiance
    // is the emission divided by it (emission 1 or 2).
    const double claimed = areaPdf(scene, lights, toV(p), toV(s.wi));
    if (!(std::abs(s.pdf - claimed) <= 1e-3 * claimed)) ++pdfMismatches;
    // What MIS asks of the light set for the triangle the direction reaches.
    for (uint32_t t = 0; t < scene.mesh.triangleCount(); ++t) {
      const V a = toV(scene.mesh.vertex(t, 0)), b = toV(scene.mesh.vertex(t, 1)),
              c = toV(scene.mesh.vertex(t, 2));
      if (const auto dist = hit(toV(p), toV(s.wi), a, b, c)) {
        const V n = unitV(crossV(sub(b, a), sub(c, a)));
        const float cosLight = static_cast<float>(std::abs(dotV(n, toV(s.wi))));
        const double asked = lights.emitterPdf(p, t, static_cast<float>(*dist), cosLight);
        if (!(std::abs(asked - claimed) <= 1e-3 * claimed)) ++pdfMismatches;
      }
    }
    const double le = s.radiance.x * s.pdf;
    if (!(std::abs(le - 1.0) < 1e-3 || std::abs(le - 2.0) < 2e-3)) ++radianceMismatches;
  }
  // Rays that graze a triangle's edge in float may miss it in double: a few in 10^6.
  EXPECT_LE(pdfMismatches, 10);
  EXPECT_LE(radianceMismatches, 10);
  const auto pdf = [&](double cosTheta, double phi) {
    return areaPdf(scene, lights, toV(p), direction(cosTheta, phi));
  };
  const auto r = test::chiSquareTest(h.counts, h.expected(pdf, kSamples, 1e-6, 8));
  EXPECT_TRUE(r.accepted()) << r.describe();
}

// The environment seen from a surface (cosine-weighted about the normal) and from a
// medium (uniform over the sphere); the pdf is read back from the sample's weight,
// radiance = L / pdf with L = 1 and one sample.
void checkEnvironment(const Vec3* normal, uint64_t seed) {
  World scene;
  Light env;
  env.type = LightType::Environment;
  env.intensity = RGB(1.0f);
  scene.lights.push_back(env);
  const LightSet lights(scene, 1);
  Rng rng(seed, 0);
  test::SphereHistogram h(20, 40);
  int pdfMismatches = 0;
  const auto pdfOf = [&](V w) {
    if (!normal) return 1.0 / (4.0 * kPi);
    return std::max(0.0, dotV(w, toV(*normal))) / kPi;
  };
  for (int i = 0; i < kSamples; ++i)
    lights.forEachAreaSample(Vec3(0.0f), normal, rng, [&](const LightSample& s) {
      h.add(s.wi.x, s.wi.y, s.wi.z);
      const double claimed = 1.0 / s.radiance.x, truth = pdfOf(toV(s.wi));
      // Below 1e-6 the light set clamps the pdf (cosine samples at the horizon).
      if (truth > 1e-6 && !(std::abs(claimed - truth) <= 1e-3 * truth)) ++pdfMismatches;
    });
  EXPECT_EQ(pdfMismatches, 0);
  const auto pdf = [&](double cosTheta, double phi) { return pdfOf(direction(cosTheta, phi)); };
  const auto r = test::chiSquareTest(h.counts, h.expected(pdf, kSamples));
  EXPECT_TRUE(r.accepted()) << r.describe();
}

TEST(LightSamplingChiSquare, EnvironmentCosineAboutANormal) {
  const Vec3 n = normalize(Vec3(0.2f, -0.3f, 0.9f));
  checkEnvironment(&n, 21);
}

TEST(LightSamplingChiSquare, EnvironmentUniformInMedia) { checkEnvironment(nullptr, 22); }

}  // namespace
}  // namespace lvox
