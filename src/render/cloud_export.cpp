#include "src/render/cloud_export.h"

#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>

#include <bit>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>

#include "src/core/error.h"
#include "src/core/image_io.h"

namespace lvox {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLY writer writes the host's floats as little-endian");

template <class T>
void put(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

void writePly(const std::string& path, const ExportedCloud& c) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment lvox point cloud: kind 0 surfels, kind 1 lvoxels; scene units\n"
      << "comment radiance_* and back_*: cached radiance, W/(m^2 sr); red green blue: its "
         "preview\n"
      << "element vertex " << c.size() << "\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "radius", "radiance_r", "radiance_g",
                        "radiance_b", "back_r", "back_g", "back_b", "sigma_t"})
    out << "property float " << p << "\n";
  out << "property uchar kind\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "end_header\n";
  for (size_t i = 0; i < c.size(); ++i) {
    for (const Vec3& v : {c.position[i], c.normal[i]})
      for (int a = 0; a < 3; ++a) put(out, v[a]);
    put(out, c.radius[i]);
    for (const RGB& v : {c.radiance[i], c.radianceBack[i]})
      for (int a = 0; a < 3; ++a) put(out, v[a]);
    put(out, c.sigmaT[i]);
    put(out, static_cast<uint8_t>(c.kind[i]));
    for (int a = 0; a < 3; ++a) put(out, toneMap(c.radiance[i][a]));
  }
  out.close();
  if (!out) throw std::runtime_error("cannot write the PLY");
}

template <class T, class Source>
std::vector<T> converted(const std::vector<Source>& values) {
  std::vector<T> out;
  out.reserve(values.size());
  for (const Source& v : values) {
    if constexpr (std::is_same_v<T, openvdb::Vec3f>)
      out.emplace_back(v[0], v[1], v[2]);
    else
      out.push_back(static_cast<T>(v));
  }
  return out;
}

// The points bucketed by OpenVDB's point index grid, each attribute copied in through it.
openvdb::points::PointDataGrid::Ptr pointGrid(const ExportedCloud& c) {
  using namespace openvdb::points;
  const std::vector<openvdb::Vec3f> positions = converted<openvdb::Vec3f>(c.position);
  const PointAttributeVector<openvdb::Vec3f> wrapper(positions);
  const float voxelSize = computeVoxelSize(wrapper, 8);
  const auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
  const auto index =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(wrapper, *transform);
  auto grid = createPointDataGrid<NullCodec, PointDataGrid>(*index, wrapper, *transform);
  auto attribute = [&](const std::string& name, const auto& values) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    appendAttribute<T>(grid->tree(), name);
    populateAttribute(grid->tree(), index->tree(), name, PointAttributeVector<T>(values));
  };
  attribute("N", converted<openvdb::Vec3f>(c.normal));
  attribute("pscale", c.radius);
  attribute("Cd", converted<openvdb::Vec3f>(c.radiance));
  attribute("radiance_back", converted<openvdb::Vec3f>(c.radianceBack));
  attribute("sigma_t", c.sigmaT);
  attribute("kind", converted<int32_t>(c.kind));
  grid->setName("points");
  return grid;
}

void writeVdb(const std::string& path, const ExportedCloud& c) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  openvdb::io::File file(path);
  file.write({pointGrid(c)});
  file.close();
}

}  // namespace

void ExportedCloud::add(CloudPointKind k, const Vec3& p, const Vec3& n, float r, const RGB& front,
                        const RGB& back, float extinction) {
  kind.push_back(k);
  position.push_back(p);
  normal.push_back(n);
  radius.push_back(r);
  radiance.push_back(front);
  radianceBack.push_back(back);
  sigmaT.push_back(extinction);
}

ExportedCloud exportCloud(const PointCloud& cloud, const SurfaceHitLight* deltaLight) {
  ExportedCloud out;
  const CloudSurfels& s = cloud.surfels();
  for (size_t i = 0; i < s.size(); ++i) {
    RGB front = s.radianceFront[i], back = s.radianceBack[i];
    if (deltaLight) {
      front += deltaLight->reflected(s.position(i), s.normal(i), s.albedo[i]);
      back += deltaLight->reflected(s.position(i), -s.normal(i), s.albedo[i]);
    }
    out.add(CloudPointKind::kSurfel, s.position(i), s.normal(i), s.radius(i), front, back, 0.0f);
  }
  const LvoxelSet& l = cloud.lvoxels();
  for (size_t i = 0; i < l.size(); ++i) {
    const RGB source = l.sourceRadiance(i);
    out.add(CloudPointKind::kLvoxel, l.position[i], Vec3(0.0f), l.halfSize[i], source, source,
            average(l.sigmaT(i)));
  }
  return out;
}

void checkCloudPath(const std::string& path, const std::string& field) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".ply" && ext != ".vdb") throw InputError(path, field, "must end in .ply or .vdb");
}

void writeCloud(const std::string& path, const ExportedCloud& cloud, OutputSet* set) {
  const bool ply = std::filesystem::path(path).extension() == ".ply";
  auto write = [&](const std::string& tmp) { ply ? writePly(tmp, cloud) : writeVdb(tmp, cloud); };
  if (set)
    set->stage(path, write);
  else
    publishAtomically(path, write);
}

}  // namespace lvox
