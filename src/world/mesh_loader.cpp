#include "src/world/mesh_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_obj_loader.h>

#include <assimp/Importer.hpp>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "src/core/error.h"
#include "src/world/obj_validate.h"
#include "src/world/ply_validate.h"
#include "src/world/surface_textures.h"

namespace lvox {
namespace {

void requireReadable(const std::string& path, const std::string& field) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, field, std::string("cannot open: ") + std::strerror(errno));
}

uint32_t materialIndex(World& world, const Material& material) {
  for (size_t i = 0; i < world.materials.size(); ++i)
    if (world.materials[i].name == material.name) return static_cast<uint32_t>(i);
  world.materials.push_back(material);
  return static_cast<uint32_t>(world.materials.size() - 1);
}

// A texture an MTL file names (relative to the MTL file's folder; '\\' separators as some
// exporters write them), checked readable now: a render never starts with a missing map.
int mtlTexture(World& world, std::string name, const std::string& mtlFile,
               const std::string& material, const std::string& map) {
  std::replace(name.begin(), name.end(), '\\', '/');
  const std::filesystem::path path =
      (std::filesystem::path(mtlFile).parent_path() / name).lexically_normal();
  const TextureFile file{path.string(), mtlFile, "material '" + material + "': " + map};
  requireReadableTexture(file);
  return world.textureIndex(file);
}

float clampAlbedo(float v) { return std::clamp(v, 0.0f, 1.0f); }

}  // namespace

bool addTriangle(TriangleMesh& mesh, const Vec3& a, const Vec3& b, const Vec3& c, uint32_t material,
                 const TriangleAttributes& attributes) {
  for (const Vec3& p : {a, b, c})
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  const Vec3 n = cross(b - a, c - a);
  if (!(length(n) > 0.0f)) return false;
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  // The attribute arrays exist from the first triangle that has the attribute on.
  if (attributes.uv && mesh.uvs.empty()) mesh.uvs.assign(base, Vec2(0.0f, 0.0f));
  if (attributes.normal && mesh.normals.empty()) {
    mesh.normals.resize(base);
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      const Vec3 g = normalize(
          cross(mesh.vertex(t, 1) - mesh.vertex(t, 0), mesh.vertex(t, 2) - mesh.vertex(t, 0)));
      for (int k = 0; k < 3; ++k) mesh.normals[mesh.indices[3 * t + k]] = g;
    }
  }
  mesh.positions.insert(mesh.positions.end(), {a, b, c});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
  mesh.triangleMaterial.push_back(material);
  if (attributes.uv || !mesh.uvs.empty())
    for (int k = 0; k < 3; ++k) mesh.uvs.push_back(attributes.uv ? attributes.uv[k] : Vec2(0.0f));
  if (attributes.normal || !mesh.normals.empty()) {
    const Vec3 g = normalize(n);
    for (int k = 0; k < 3; ++k) {
      const Vec3 s = attributes.normal ? attributes.normal[k] : g;
      // A zero or non-finite normal in a file shades flat.
      const bool usable =
          std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z) && length(s) > 0.0f;
      mesh.normals.push_back(usable ? normalize(s) : g);
    }
  }
  return true;
}

MeshLoadStats loadObj(const std::string& path, const std::string& field, const Transform& xf,
                      std::optional<uint32_t> materialOverride, World& world) {
  requireReadable(path, field);
  validateObj(path, field);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = std::filesystem::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string msg = reader.Error();
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    throw InputError(path, field, "malformed OBJ: " + msg.substr(0, 300));
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const size_t vertexCount = attrib.vertices.size() / 3;

  // Scene material for each MTL material (or the override for all).
  std::vector<uint32_t> mtlToScene;
  const std::string stem = std::filesystem::path(path).stem().string();
  const std::vector<std::string> libraries = objMaterialLibraries(path);
  const std::string mtlFile = libraries.empty() ? path : libraries.front();
  if (!materialOverride) {
    for (const tinyobj::material_t& m : reader.GetMaterials()) {
      const RGB kd(clampAlbedo(m.diffuse[0]), clampAlbedo(m.diffuse[1]), clampAlbedo(m.diffuse[2]));
      const RGB ke(std::max(0.0f, m.emission[0]), std::max(0.0f, m.emission[1]),
                   std::max(0.0f, m.emission[2]));
      // The bound of a scene file's "emission": beyond it a pixel is no longer a radiance.
      if (!isFinite(ke) || maxComponent(ke) > 1e9f)
        throw InputError(path, field, "material '" + m.name + "': Ke outside [0, 1e9]");
      Material material{stem + "/" + m.name, kd, ke};
      // map_Kd replaces Kd (as Blender, Cycles and pbrt read it); map_d cuts holes.
      if (!m.diffuse_texname.empty()) {
        material.albedoMap = mtlTexture(world, m.diffuse_texname, mtlFile, m.name, "map_Kd");
        material.albedo = RGB(1.0f);
      }
      if (!m.alpha_texname.empty())
        material.opacityMap = mtlTexture(world, m.alpha_texname, mtlFile, m.name, "map_d");
      mtlToScene.push_back(materialIndex(world, material));
    }
  }
  const uint32_t defaultMaterial =
      materialOverride ? *materialOverride
                       : materialIndex(world, Material{stem + "/(default)", RGB(0.8f), RGB(0.0f)});
  const size_t uvCount = attrib.texcoords.size() / 2, normalCount = attrib.normals.size() / 3;
  std::vector<Vec3> normals(normalCount);
  for (size_t i = 0; i < normalCount; ++i)
    normals[i] = xf.normal(
        Vec3(attrib.normals[3 * i], attrib.normals[3 * i + 1], attrib.normals[3 * i + 2]));

  MeshLoadStats stats;
  std::vector<Vec3> transformed(vertexCount);
  for (size_t i = 0; i < vertexCount; ++i)
    transformed[i] = xf.point(
        Vec3(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]));
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& idx = shape.mesh.indices;
    for (size_t f = 0; f + 2 < idx.size(); f += 3) {
      Vec3 p[3], n[3];
      Vec2 uv[3];
      bool hasUv = true, hasNormal = true;
      for (int k = 0; k < 3; ++k) {
        const int vi = idx[f + k].vertex_index;
        if (vi < 0 || static_cast<size_t>(vi) >= vertexCount)
          throw InputError(path, field,
                           "face in object '" + shape.name + "' refers to vertex " +
                               std::to_string(vi + 1) + " but the file has " +
                               std::to_string(vertexCount));
        p[k] = transformed[static_cast<size_t>(vi)];
        const int ti = idx[f + k].texcoord_index, ni = idx[f + k].normal_index;
        if (ti >= 0 && static_cast<size_t>(ti) < uvCount)
          uv[k] = Vec2(attrib.texcoords[2 * static_cast<size_t>(ti)],
                       attrib.texcoords[2 * static_cast<size_t>(ti) + 1]);
        else
          hasUv = false;
        if (ni >= 0 && static_cast<size_t>(ni) < normalCount)
          n[k] = normals[static_cast<size_t>(ni)];
        else
          hasNormal = false;
      }
      const int mid = shape.mesh.material_ids[f / 3];
      uint32_t material = defaultMaterial;
      if (!materialOverride && mid >= 0 && static_cast<size_t>(mid) < mtlToScene.size())
        material = mtlToScene[static_cast<size_t>(mid)];
      const TriangleAttributes attributes{hasUv ? uv : nullptr, hasNormal ? n : nullptr};
      if (addTriangle(world.mesh, p[0], p[1], p[2], material, attributes))
        ++stats.triangles;
      else
        ++stats.skippedDegenerate;
    }
  }
  if (stats.triangles == 0) throw InputError(path, field, "the OBJ has no valid triangles");
  return stats;
}

std::vector<std::string> objMaterialLibraries(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path, std::ios::binary);
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string keyword, name;
    words >> keyword;
    if (keyword != "mtllib") continue;
    while (words >> name) out.push_back((folder / name).lexically_normal().string());
  }
  return out;
}

MeshLoadStats loadPly(const std::string& path, const std::string& field, const Transform& xf,
                      uint32_t material, World& world) {
  requireReadable(path, field);
  // Assimp trusts the header's counts and the face indices: check the whole file first.
  validatePly(path, field);
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_FindInvalidData);
  if (!ai || !ai->mRootNode) {
    std::string msg = importer.GetErrorString();
    throw InputError(path, field, "malformed PLY: " + msg.substr(0, 300));
  }
  MeshLoadStats stats;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* mesh = ai->mMeshes[m];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by triangulation
      Vec3 p[3], n[3];
      Vec2 uv[3];
      for (int k = 0; k < 3; ++k) {
        const unsigned vi = face.mIndices[k];
        if (vi >= mesh->mNumVertices)
          throw InputError(path, field,
                           "face " + std::to_string(f) + " refers to a missing vertex");
        const aiVector3D& v = mesh->mVertices[vi];
        p[k] = xf.point(Vec3(v.x, v.y, v.z));
        if (mesh->HasNormals())
          n[k] = xf.normal(Vec3(mesh->mNormals[vi].x, mesh->mNormals[vi].y, mesh->mNormals[vi].z));
        if (mesh->HasTextureCoords(0))
          uv[k] = Vec2(mesh->mTextureCoords[0][vi].x, mesh->mTextureCoords[0][vi].y);
      }
      const TriangleAttributes attributes{mesh->HasTextureCoords(0) ? uv : nullptr,
                                          mesh->HasNormals() ? n : nullptr};
      if (addTriangle(world.mesh, p[0], p[1], p[2], material, attributes))
        ++stats.triangles;
      else
        ++stats.skippedDegenerate;
    }
  }
  if (stats.triangles == 0) throw InputError(path, field, "the PLY has no valid triangles");
  return stats;
}

}  // namespace lvox
