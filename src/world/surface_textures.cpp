#include "src/world/surface_textures.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include "src/core/check.h"
#include "src/core/error.h"
#include "src/world/linear_texture_input.h"

namespace lvox {
namespace {

OIIO::TextureSystem* textureSystem(void* p) { return static_cast<OIIO::TextureSystem*>(p); }

std::string firstLine(std::string s) {
  const size_t end = s.find('\n');
  if (end != std::string::npos) s.resize(end);
  return s.substr(0, 300);
}

// Points averaged over a surfel's disk (albedoOverDisk), on Vogel's spiral.
constexpr int kDiskSamples = 16;
constexpr float kGoldenAngle = 2.39996323f;  // pi (3 - sqrt 5)

}  // namespace

struct SurfaceTextures::Texture {
  OIIO::TextureSystem::TextureHandle* handle = nullptr;
  int colorChannels = 3;  // 1 (grey) or 3
  int alphaChannel = 0;   // the channel a cut-out mask reads: alpha if there is one
  float cutBelow = 0.5f;  // a mask's value below which a point is a hole, as the mask reads it
};

void requireReadableTexture(const TextureFile& texture) {
  auto in = OIIO::ImageInput::open(texture.path);
  if (!in)
    throw InputError(texture.namedBy, texture.field,
                     "cannot read texture '" + texture.path + "': " + firstLine(OIIO::geterror()));
}

SurfaceTextures::SurfaceTextures(const World& world, TextureFilter filter)
    : world_(world), filter_(filter) {
  for (const Material& m : world.materials) anyCutouts_ = anyCutouts_ || m.opacityMap >= 0;
  if (world.textures.empty()) return;
  // OpenImageIO's process-wide TextureSystem, never destroyed: Debian's OIIO 2.4
  // TextureSystem::destroy deletes through the wrong type (AddressSanitizer's
  // new-delete-type-mismatch), so a private system per render cannot be released cleanly.
  // Each render re-reads its files, so it sees them as they are now, and reads them through
  // the reader that decodes sRGB-encoded images to linear light (linear_texture_input.h).
  OIIO::TextureSystem* ts = OIIO::TextureSystem::create(true);
  system_ = ts;
  ts->attribute("automip", 1);  // JPEG and PNG textures have no mip levels of their own
  OIIO::TextureSystem::Perthread* thread = ts->get_perthread_info();
  std::vector<bool> albedoMap(world.textures.size(), false);
  for (const Material& m : world.materials)
    if (m.albedoMap >= 0) albedoMap[static_cast<size_t>(m.albedoMap)] = true;
  for (size_t i = 0; i < world.textures.size(); ++i) {
    const TextureFile& file = world.textures[i];
    auto t = std::make_unique<Texture>();
    OIIO::ImageSpec spec;
    if (!registerTexture(file.path, albedoMap[i]) ||
        !(t->handle = ts->get_texture_handle(OIIO::ustring(file.path), thread)) ||
        !ts->get_imagespec(t->handle, thread, 0, spec))
      throw InputError(file.namedBy, file.field,
                       "cannot read texture '" + file.path + "': " + firstLine(ts->geterror()));
    t->colorChannels = spec.nchannels >= 3 ? 3 : 1;
    t->alphaChannel = spec.alpha_channel >= 0 ? spec.alpha_channel : 0;
    // A mask without alpha that is also an albedo map reads its decoded grey: the cut stays
    // where the stored value is 1/2.
    if (spec.alpha_channel < 0 && spec.get_int_attribute(kDecodedAttribute) != 0)
      t->cutBelow = srgbToLinear(0.5f);
    handles_.push_back(std::move(t));
  }
}

SurfaceTextures::~SurfaceTextures() = default;

Vec2 SurfaceTextures::uvDelta(uint32_t tri, const Vec3& d) const {
  const TriangleMesh& mesh = world_.mesh;
  if (mesh.uvs.empty() || (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f)) return Vec2(0.0f);
  // d = e1 a + e2 b in the plane (least squares), and the uv edges map (a, b) to uv.
  const Vec3 p0 = mesh.vertex(tri, 0);
  const Vec3 e1 = mesh.vertex(tri, 1) - p0, e2 = mesh.vertex(tri, 2) - p0;
  const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  const float det = d11 * d22 - d12 * d12;
  if (!(det > 0.0f)) return Vec2(0.0f);
  const float r1 = dot(d, e1), r2 = dot(d, e2);
  const float a = (d22 * r1 - d12 * r2) / det, b = (d11 * r2 - d12 * r1) / det;
  const Vec2 uv0 = mesh.uvs[mesh.indices[3 * tri]];
  const Vec2 du = (mesh.uvs[mesh.indices[3 * tri + 1]] - uv0) * a +
                  (mesh.uvs[mesh.indices[3 * tri + 2]] - uv0) * b;
  return Vec2(du.x, -du.y);  // texture t runs down the image, v up
}

RGB SurfaceTextures::albedo(uint32_t tri, float b1, float b2, const Vec3& dpdx,
                            const Vec3& dpdy) const {
  const Material& m = world_.materials[world_.mesh.triangleMaterial[tri]];
  LVOX_DCHECK(m.albedoMap >= 0, "albedo lookup on a material without a map");
  const Texture& tex = *handles_[static_cast<size_t>(m.albedoMap)];
  const Vec2 uv = world_.mesh.uvs.empty() ? Vec2(0.0f) : world_.mesh.uvAt(tri, b1, b2);
  const Vec2 dx = uvDelta(tri, dpdx), dy = uvDelta(tri, dpdy);
  OIIO::TextureOpt opt;
  opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  if (filter_ == TextureFilter::kNearest) {
    opt.interpmode = OIIO::TextureOpt::InterpClosest;
    opt.mipmode = OIIO::TextureOpt::MipModeNoMIP;
  } else {
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  }
  float out[3] = {0.0f, 0.0f, 0.0f};
  OIIO::TextureSystem* ts = textureSystem(system_);
  ts->texture(tex.handle, ts->get_perthread_info(), opt, uv.x, 1.0f - uv.y, dx.x, dx.y, dy.x, dy.y,
              tex.colorChannels, out);
  if (tex.colorChannels == 1) out[1] = out[2] = out[0];
  // Linear light already (registerTexture). A float image's NaN reflects nothing.
  RGB c;
  for (int k = 0; k < 3; ++k) c[k] = out[k] > 0.0f ? std::min(out[k], 1.0f) : 0.0f;
  return c * m.albedo;
}

RGB SurfaceTextures::albedoOverDisk(uint32_t tri, float b1, float b2, float radius) const {
  // Point lookups averaged: a spiral of kDiskSamples points covers the disk evenly, and
  // those off the triangle are skipped, since its texture coordinates mean nothing there
  // (an atlas). Until stop 52 this was also what kept the average in linear light, when
  // OpenImageIO's filters averaged encoded texels (docs/pcb.md, "A surfel's albedo").
  const TriangleMesh& mesh = world_.mesh;
  const Vec3 p0 = mesh.vertex(tri, 0);
  const Vec3 e1 = mesh.vertex(tri, 1) - p0, e2 = mesh.vertex(tri, 2) - p0;
  const Vec3 normal = cross(e1, e2);
  const Vec3 point(0.0f);  // no footprint: the finest level
  if (!(dot(normal, normal) > 0.0f)) return albedo(tri, b1, b2, point, point);
  const Vec3 s = normalize(e1), t = normalize(cross(normal, e1));
  const Vec3 centre = p0 + e1 * b1 + e2 * b2;
  RGB sum(0.0f);
  int inside = 0;
  for (int k = 0; k < kDiskSamples; ++k) {
    const float r = radius * std::sqrt((static_cast<float>(k) + 0.5f) / kDiskSamples);
    const float phi = kGoldenAngle * static_cast<float>(k);
    const Vec2 b =
        mesh.barycentricOf(tri, centre + s * (r * std::cos(phi)) + t * (r * std::sin(phi)));
    if (!(b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f)) continue;  // NaN: off too
    sum += albedo(tri, b.x, b.y, point, point);
    ++inside;
  }
  return inside > 0 ? sum / static_cast<float>(inside) : albedo(tri, b1, b2, point, point);
}

bool SurfaceTextures::isCutAway(uint32_t tri, float b1, float b2) const {
  const int map = opacityMapOf(tri);
  if (map < 0) return false;
  const Texture& tex = *handles_[static_cast<size_t>(map)];
  const Vec2 uv = world_.mesh.uvs.empty() ? Vec2(0.0f) : world_.mesh.uvAt(tri, b1, b2);
  OIIO::TextureOpt opt;
  opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  opt.firstchannel = tex.alphaChannel;
  opt.mipmode = OIIO::TextureOpt::MipModeNoMIP;
  opt.interpmode = filter_ == TextureFilter::kNearest ? OIIO::TextureOpt::InterpClosest
                                                      : OIIO::TextureOpt::InterpBilinear;
  float opacity = 1.0f;
  OIIO::TextureSystem* ts = textureSystem(system_);
  ts->texture(tex.handle, ts->get_perthread_info(), opt, uv.x, 1.0f - uv.y, 0.0f, 0.0f, 0.0f, 0.0f,
              1, &opacity);
  return opacity < tex.cutBelow;
}

}  // namespace lvox
