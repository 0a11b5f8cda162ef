#include "src/geometry/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace lvox {

// The triangles of one Embree geometry, and where the cut-out filter finds them.
struct CutoutGeometry {
  const SurfaceTextures* textures = nullptr;
  std::vector<uint32_t> triangles;  // mesh triangle of each primitive
};

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // Geometry 0 holds every triangle, in mesh order, unless some have cut-outs: then
  // geometry 0 holds the others and geometry 1 those, each mapping primitives back.
  std::vector<uint32_t> opaqueTriangles;  // empty: primitive = mesh triangle
  CutoutGeometry cutouts;
  uint32_t triangleOf(unsigned geomID, unsigned primID) const {
    if (geomID == 1) return cutouts.triangles[primID];
    return opaqueTriangles.empty() ? primID : opaqueTriangles[primID];
  }
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void throwOnDeviceError(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error during ") + what + " (code " +
                             std::to_string(static_cast<int>(err)) + ")");
}

RTCRay makeRay(const Ray& ray) {
  RTCRay r{};
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.tnear = ray.tmin;
  r.tfar = ray.tmax;
  r.mask = 0xFFFFFFFFu;
  r.time = 0.0f;
  r.flags = 0;
  return r;
}

// Rejects candidate hits on cut-away texels (closest hits and shadow rays).
void cutoutFilter(const RTCFilterFunctionNArguments* args) {
  const auto* geometry = static_cast<const CutoutGeometry*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t tri = geometry->triangles[RTCHitN_primID(args->hit, args->N, i)];
    if (geometry->textures->isCutAway(tri, RTCHitN_u(args->hit, args->N, i),
                                      RTCHitN_v(args->hit, args->N, i)))
      args->valid[i] = 0;
  }
}

void attachTriangles(RTCDevice device, RTCScene scene, const TriangleMesh& mesh,
                     const std::vector<uint32_t>* subset, CutoutGeometry* cutouts,
                     unsigned geomID) {
  const size_t count = subset ? subset->size() : mesh.triangleCount();
  if (count == 0) return;
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree-owned copies: Embree pads them as its SIMD loads require.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.positions.size()));
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), count));
  if (subset) {
    for (size_t p = 0; p < count; ++p)
      for (int k = 0; k < 3; ++k) indices[3 * p + k] = mesh.indices[3 * (*subset)[p] + k];
  } else {
    std::copy(mesh.indices.begin(), mesh.indices.end(), indices);
  }
  if (cutouts) {
    rtcSetGeometryUserData(geom, cutouts);
    rtcSetGeometryIntersectFilterFunction(geom, cutoutFilter);
    rtcSetGeometryOccludedFilterFunction(geom, cutoutFilter);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, geomID);
  rtcReleaseGeometry(geom);
}

}  // namespace

RayTracer::RayTracer(const TriangleMesh& mesh, const SurfaceTextures* textures)
    : impl_(std::make_unique<Impl>()), mesh_(mesh), textures_(textures) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust traversal: no rays slip through shared triangle edges.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (textures && textures->anyCutouts()) {
    impl_->cutouts.textures = textures;
    for (uint32_t t = 0; t < mesh.triangleCount(); ++t)
      (textures->hasCutout(t) ? impl_->cutouts.triangles : impl_->opaqueTriangles).push_back(t);
    attachTriangles(impl_->device, impl_->scene, mesh, &impl_->opaqueTriangles, nullptr, 0);
    attachTriangles(impl_->device, impl_->scene, mesh, &impl_->cutouts.triangles, &impl_->cutouts,
                    1);
  } else {
    attachTriangles(impl_->device, impl_->scene, mesh, nullptr, nullptr, 0);
  }
  rtcCommitScene(impl_->scene);
  throwOnDeviceError(impl_->device, "BVH build");

  Bounds3 b;
  for (const Vec3& p : mesh.positions) b.extend(p);
  if (!b.empty()) {
    const Vec3 d = b.diagonal();
    const float extent =
        std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z), std::abs(b.hi.x),
                  std::abs(b.hi.y), std::abs(b.hi.z), d.x, d.y, d.z});
    // Float spacing at the scene's largest coordinate, with a generous margin.
    epsilon_ = std::max(1e-5f, extent * 2e-5f);
  }
}

RayTracer::~RayTracer() = default;

bool RayTracer::intersect(const Ray& ray, SurfaceHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray = makeRay(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.triangle = impl_->triangleOf(rh.hit.geomID, rh.hit.primID);
  hit.point = ray.at(hit.t);
  hit.b1 = rh.hit.u;
  hit.b2 = rh.hit.v;
  const Vec3 a = mesh_.vertex(hit.triangle, 0);
  Vec3 n = normalize(cross(mesh_.vertex(hit.triangle, 1) - a, mesh_.vertex(hit.triangle, 2) - a));
  if (dot(n, ray.dir) > 0.0f) n = -n;
  hit.normal = n;
  hit.shading = n;
  if (!mesh_.normals.empty()) {
    // Smooth normals shade on the side the ray sees, like the geometric one.
    const Vec3 s = mesh_.shadingNormalAt(hit.triangle, hit.b1, hit.b2);
    hit.shading = dot(s, n) < 0.0f ? -s : s;
  }
  return true;
}

bool RayTracer::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = makeRay(ray);
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar < 0.0f;
}

}  // namespace lvox
