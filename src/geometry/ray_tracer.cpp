#include "src/geometry/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace lvox {

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
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

}  // namespace

RayTracer::RayTracer(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()), mesh_(mesh) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust traversal: no rays slip through shared triangle edges.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (mesh.triangleCount() > 0) {
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree-owned copies: Embree pads them as its SIMD loads require.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), mesh.triangleCount()));
    std::copy(mesh.indices.begin(), mesh.indices.end(), indices);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
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
  hit.triangle = rh.hit.primID;
  hit.point = ray.at(hit.t);
  const Vec3 a = mesh_.vertex(hit.triangle, 0);
  Vec3 n = normalize(cross(mesh_.vertex(hit.triangle, 1) - a, mesh_.vertex(hit.triangle, 2) - a));
  if (dot(n, ray.dir) > 0.0f) n = -n;
  hit.normal = n;
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
