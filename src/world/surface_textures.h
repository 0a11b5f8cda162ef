#pragma once
// The images materials read (albedo maps, cut-out masks), through OpenImageIO's shared
// TextureSystem: filtered, mip-mapped lookups (mip levels are made on the fly for images
// that have none), thread-safe, each thread with its own OIIO handle. This header hides
// OpenImageIO: only surface_textures.cpp includes it.
#include <cstdint>
#include <memory>
#include <vector>

#include "src/world/world.h"

namespace lvox {

// Throws an InputError naming the file that names the texture and its field unless
// OpenImageIO can open the image.
void requireReadableTexture(const TextureFile& texture);

enum class TextureFilter {
  kFiltered,  // trilinear mip-mapping over the footprint, bilinear within a level
  kNearest,   // the texel under the point, finest level
};

class SurfaceTextures {
 public:
  // Opens every texture of `world` (a world with none never starts OpenImageIO), re-read
  // from disk.
  explicit SurfaceTextures(const World& world, TextureFilter filter = TextureFilter::kFiltered);
  ~SurfaceTextures();
  SurfaceTextures(const SurfaceTextures&) = delete;
  SurfaceTextures& operator=(const SurfaceTextures&) = delete;

  bool empty() const { return handles_.empty(); }
  // Whether any triangle's material has a cut-out mask.
  bool anyCutouts() const { return anyCutouts_; }
  bool hasCutout(uint32_t triangle) const { return opacityMapOf(triangle) >= 0; }

  // Albedo of a triangle with an albedo map, at barycentrics (b1, b2), averaged over the
  // footprint spanned by the world-space vectors dpdx and dpdy in its plane (zero vectors:
  // a point lookup at the finest level). Integer images are sRGB-encoded, float images
  // linear; either reaches the filter in linear light (linear_texture_input.h), and the
  // result is linear, times the material's albedo factor.
  RGB albedo(uint32_t triangle, float b1, float b2, const Vec3& dpdx, const Vec3& dpdy) const;
  // Albedo averaged over the part of a disk of `radius` around the point (a surfel's
  // footprint) that lies on the triangle: the mean of point lookups on a spiral over the
  // disk, where albedo() over the disk's footprint would blend in what the texture holds off
  // the triangle (an atlas's other surfaces).
  RGB albedoOverDisk(uint32_t triangle, float b1, float b2, float radius) const;
  // Whether the point at barycentrics (b1, b2) of a triangle with a cut-out is a hole.
  bool isCutAway(uint32_t triangle, float b1, float b2) const;

 private:
  struct Texture;
  int opacityMapOf(uint32_t triangle) const {
    return world_.materials[world_.mesh.triangleMaterial[triangle]].opacityMap;
  }
  // Texture-space (s, t) derivatives of a world-space vector in the triangle's plane.
  Vec2 uvDelta(uint32_t triangle, const Vec3& d) const;

  const World& world_;
  TextureFilter filter_;
  bool anyCutouts_ = false;
  void* system_ = nullptr;  // OIIO::TextureSystem
  std::vector<std::unique_ptr<Texture>> handles_;
};

// Albedo of a material at a hit: its constant albedo unless it has an albedo map (then one
// lookup over the footprint dpdx, dpdy). Untextured materials cost one comparison.
inline RGB albedoAt(const SurfaceTextures* textures, const Material& m, uint32_t triangle, float b1,
                    float b2, const Vec3& dpdx = Vec3(0.0f), const Vec3& dpdy = Vec3(0.0f)) {
  if (m.albedoMap < 0 || !textures) return m.albedo;
  return textures->albedo(triangle, b1, b2, dpdx, dpdy);
}

}  // namespace lvox
