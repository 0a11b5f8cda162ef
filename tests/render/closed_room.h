#pragma once
// The six quads of a closed room, 2 x 2 x 2 from (-1, 0, -1) to (1, 2, 1), as the JSON of
// a scene's "shapes" list (without the brackets): the tests of light that must not leak
// through its walls put media across them.
#include <string>

namespace lvox::test {

inline std::string closedRoomWalls(const std::string& material) {
  const char* quads[] = {"[[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]]",
                         "[[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]]",
                         "[[-1, 0, -1], [-1, 2, -1], [-1, 2, 1], [-1, 0, 1]]",
                         "[[1, 0, -1], [1, 2, -1], [1, 2, 1], [1, 0, 1]]",
                         "[[-1, 0, -1], [1, 0, -1], [1, 2, -1], [-1, 2, -1]]",
                         "[[-1, 0, 1], [1, 0, 1], [1, 2, 1], [-1, 2, 1]]"};
  std::string walls;
  for (const char* q : quads)
    walls += std::string(walls.empty() ? "" : ", ") + R"({"type": "quad", "material": ")" +
             material + R"(", "corners": )" + q + "}";
  return walls;
}

}  // namespace lvox::test
