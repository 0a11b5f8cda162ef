#include "src/world/world.h"

namespace lvox {

Ray Camera::generateRay(float px, float py) const {
  const Vec3 forward = normalize(lookAt - position);
  const Vec3 right = normalize(cross(forward, up));
  const Vec3 trueUp = cross(right, forward);
  const float tanHalf = std::tan(0.5f * vfovDeg * kPi / 180.0f);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float sx = (2.0f * px / static_cast<float>(width) - 1.0f) * tanHalf * aspect;
  const float sy = (1.0f - 2.0f * py / static_cast<float>(height)) * tanHalf;
  Ray r;
  r.origin = position;
  r.dir = normalize(forward + right * sx + trueUp * sy);
  return r;
}

float Light::spotFactor(const Vec3& dirFromLight) const {
  const float cosAngle = dot(dirFromLight, direction);
  const float cosEdge = std::cos(coneDeg * kPi / 180.0f);
  const float cosInner = std::cos((coneDeg - falloffDeg) * kPi / 180.0f);
  if (cosAngle >= cosInner) return 1.0f;
  if (cosAngle <= cosEdge) return 0.0f;
  const float x = (cosAngle - cosEdge) / (cosInner - cosEdge);
  return x * x * (3.0f - 2.0f * x);
}

Vec2 TriangleMesh::barycentricOf(size_t tri, const Vec3& p) const {
  const Vec3 a = vertex(tri, 0);
  const Vec3 e1 = vertex(tri, 1) - a, e2 = vertex(tri, 2) - a, d = p - a;
  const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  const float d1 = dot(d, e1), d2 = dot(d, e2);
  const float det = d11 * d22 - d12 * d12;
  if (!(det > 0.0f)) return Vec2(0.0f, 0.0f);
  return Vec2((d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det);
}

int World::textureIndex(const TextureFile& file) {
  for (size_t i = 0; i < textures.size(); ++i)
    if (textures[i].path == file.path) return static_cast<int>(i);
  textures.push_back(file);
  return static_cast<int>(textures.size() - 1);
}

Bounds3 World::bounds() const {
  Bounds3 b;
  for (const Vec3& p : mesh.positions) b.extend(p);
  return b;
}

}  // namespace lvox
