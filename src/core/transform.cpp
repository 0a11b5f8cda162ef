#include "src/core/math.h"

namespace lvox {

Transform Transform::operator*(const Transform& o) const {
  Transform r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      float s = 0.0f;
      for (int k = 0; k < 4; ++k) s += m[i][k] * o.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

float Transform::determinant3() const {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Transform Transform::inverse() const {
  // Affine inverse: invert the 3x3 part by cofactors, then the translation.
  const float det = determinant3();
  const float inv = 1.0f / det;
  Transform r;
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv;
  for (int i = 0; i < 3; ++i)
    r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
  return r;
}

Vec3 Transform::normal(const Vec3& n) const {
  const Transform inv = inverse();
  // Multiply by the transpose of the inverse's linear part.
  return normalize(Vec3(inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
                        inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
                        inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z));
}

bool Transform::isIdentity() const {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (m[i][j] != (i == j ? 1.0f : 0.0f)) return false;
  return true;
}

Transform Transform::translate(const Vec3& t) {
  Transform r;
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Transform Transform::scale(const Vec3& s) {
  Transform r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Transform Transform::rotate(const Vec3& axis, float degrees) {
  // Rodrigues' rotation about a unit axis.
  const Vec3 a = normalize(axis);
  const float th = degrees * kPi / 180.0f;
  const float c = std::cos(th), s = std::sin(th), k = 1.0f - c;
  Transform r;
  r.m[0][0] = c + a.x * a.x * k;
  r.m[0][1] = a.x * a.y * k - a.z * s;
  r.m[0][2] = a.x * a.z * k + a.y * s;
  r.m[1][0] = a.y * a.x * k + a.z * s;
  r.m[1][1] = c + a.y * a.y * k;
  r.m[1][2] = a.y * a.z * k - a.x * s;
  r.m[2][0] = a.z * a.x * k - a.y * s;
  r.m[2][1] = a.z * a.y * k + a.x * s;
  r.m[2][2] = c + a.z * a.z * k;
  return r;
}

}  // namespace lvox
