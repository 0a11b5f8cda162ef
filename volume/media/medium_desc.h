#pragma once
// What a scene file says about one participating medium (an entry of "media"), validated
// but not loaded: MediaSet::build turns descriptions into media (and reads the VDB files).
#include <string>

#include "src/core/json_fields.h"
#include "src/core/math.h"
#include "volume/phase.h"

namespace lvox {

enum class MediumType { Vdb, Homogeneous, Procedural };
enum class ProceduralKind { Constant, LinearRamp, GaussianBlob, Noise };

struct MediumDesc {
  MediumType type = MediumType::Homogeneous;
  std::string field;  // "media[i]", for error messages
  // vdb
  std::string file;  // absolute path
  std::string grid = "density";
  std::string emissionGrid;  // optional
  // Blackbody emission (volume/media/blackbody.h): T = temperature x the grid's value.
  std::string temperatureGrid;  // optional
  float temperature = 1000.0f;  // kelvin per unit of the temperature grid
  float blackbodyIntensity = 1.0f;
  float densityScale = 1.0f;
  RGB albedo{0.8f, 0.8f, 0.8f};
  RGB emission{0.0f, 0.0f, 0.0f};  // Le multiplied by sigma_a (and the emission grid)
  Transform transform;
  // homogeneous and procedural: the box
  Vec3 boxMin{-1, -1, -1};
  Vec3 boxMax{1, 1, 1};
  RGB sigmaA{0, 0, 0};
  RGB sigmaS{0, 0, 0};
  // procedural (density multiplies sigma_a/sigma_s of the box)
  ProceduralKind procedural = ProceduralKind::Constant;
  Vec3 gradient{0, 0, 0};  // linear ramp: density = 1 + dot(gradient, p - boxMin)
  Vec3 center{0, 0, 0};    // gaussian blob centre
  float radius = 1.0f;     // gaussian blob std-dev
  float frequency = 1.0f;  // noise: cycles per unit
  // phase function
  PhaseKind phase = PhaseKind::Isotropic;
  float g = 0.0f;
};

// Reads one entry of "media" (its field path is `m`'s); unknown keys and out-of-range
// values throw InputError. Relative file names are resolved against the scene's folder.
MediumDesc parseMedium(JsonObject m);

}  // namespace lvox
