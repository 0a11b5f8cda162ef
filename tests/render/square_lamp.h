#pragma once
// The square lamp the light-sampling tests look at: 2 x 2 in the plane z = 1, centred on
// the z axis, two triangles of material 0 (a lamp of the given radiance).
#include "src/world/mesh_loader.h"
#include "src/world/world.h"

namespace lvox::test {

inline World squareLampWorld(float emission) {
  World world;
  world.materials.push_back(Material{"lamp", RGB(0.0f), RGB(emission)});
  const Vec3 a(-1, -1, 1), b(1, -1, 1), c(1, 1, 1), d(-1, 1, 1);
  addTriangle(world.mesh, a, b, c, 0);
  addTriangle(world.mesh, a, c, d, 0);
  return world;
}

}  // namespace lvox::test
