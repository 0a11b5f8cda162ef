#include "src/world/gltf_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "src/core/error.h"
#include "src/world/surface_textures.h"

namespace lvox {
namespace {

Transform toTransform(const aiMatrix4x4& a) {
  Transform t;
  const float rows[4][4] = {
      {a.a1, a.a2, a.a3, a.a4}, {a.b1, a.b2, a.b3, a.b4}, {a.c1, a.c2, a.c3, a.c4}, {0, 0, 0, 1}};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) t.m[r][c] = rows[r][c];
  return t;
}

float unit(float v) { return std::clamp(v, 0.0f, 1.0f); }

Material gltfMaterial(const aiMaterial& mat, size_t index, const std::string& path, World& world) {
  const std::string stem = std::filesystem::path(path).stem().string();
  std::string name = mat.GetName().C_Str();
  if (name.empty()) name = "material" + std::to_string(index);
  Material m;
  m.name = stem + "/" + name;
  aiColor4D base(0.8f, 0.8f, 0.8f, 1.0f);
  if (mat.Get(AI_MATKEY_BASE_COLOR, base) != AI_SUCCESS) mat.Get(AI_MATKEY_COLOR_DIFFUSE, base);
  m.albedo = RGB(unit(base.r), unit(base.g), unit(base.b));
  aiColor3D emissive(0.0f, 0.0f, 0.0f);
  mat.Get(AI_MATKEY_COLOR_EMISSIVE, emissive);
  float strength = 1.0f;
  mat.Get(AI_MATKEY_EMISSIVE_INTENSITY, strength);
  m.emission = RGB(emissive.r, emissive.g, emissive.b) * strength;
  if (!isFinite(m.emission) || maxComponent(m.emission) > 1e9f ||
      std::min({m.emission.x, m.emission.y, m.emission.z}) < 0.0f)
    throw InputError(path, "material '" + name + "'", "emission outside [0, 1e9]");
  aiString texture;
  if (mat.GetTexture(aiTextureType_BASE_COLOR, 0, &texture) == AI_SUCCESS ||
      mat.GetTexture(aiTextureType_DIFFUSE, 0, &texture) == AI_SUCCESS) {
    const std::string uri = texture.C_Str();
    const std::string field = "material '" + name + "': baseColorTexture";
    if (uri.empty() || uri[0] == '*')
      throw InputError(path, field,
                       "embedded images are not supported: save the texture as a file beside "
                       "the glTF and reference it by its URI");
    const TextureFile file{
        (std::filesystem::path(path).parent_path() / uri).lexically_normal().string(), path, field};
    requireReadableTexture(file);
    m.albedoMap = world.textureIndex(file);
  }
  return m;
}

uint32_t addMaterial(World& world, const Material& m) {
  for (size_t i = 0; i < world.materials.size(); ++i)
    if (world.materials[i].name == m.name) return static_cast<uint32_t>(i);
  world.materials.push_back(m);
  return static_cast<uint32_t>(world.materials.size() - 1);
}

void addMesh(const aiMesh& mesh, const Transform& xf, uint32_t material, World& world,
             MeshLoadStats& stats) {
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines
    Vec3 p[3], n[3];
    Vec2 uv[3];
    for (int k = 0; k < 3; ++k) {
      const unsigned vi = face.mIndices[k];
      if (vi >= mesh.mNumVertices) throw std::out_of_range("glTF face index");
      const aiVector3D& v = mesh.mVertices[vi];
      p[k] = xf.point(Vec3(v.x, v.y, v.z));
      if (mesh.HasNormals())
        n[k] = xf.normal(Vec3(mesh.mNormals[vi].x, mesh.mNormals[vi].y, mesh.mNormals[vi].z));
      if (mesh.HasTextureCoords(0))
        uv[k] = Vec2(mesh.mTextureCoords[0][vi].x, mesh.mTextureCoords[0][vi].y);
    }
    const TriangleAttributes attributes{mesh.HasTextureCoords(0) ? uv : nullptr,
                                        mesh.HasNormals() ? n : nullptr};
    if (addTriangle(world.mesh, p[0], p[1], p[2], material, attributes))
      ++stats.triangles;
    else
      ++stats.skippedDegenerate;
  }
}

void addNode(const aiScene& ai, const aiNode& node, const Transform& parent,
             const std::vector<uint32_t>& materials, World& world, MeshLoadStats& stats) {
  const Transform xf = parent * toTransform(node.mTransformation);
  for (unsigned i = 0; i < node.mNumMeshes; ++i) {
    const aiMesh& mesh = *ai.mMeshes[node.mMeshes[i]];
    addMesh(mesh, xf, materials[mesh.mMaterialIndex], world, stats);
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    addNode(ai, *node.mChildren[c], xf, materials, world, stats);
}

// The node transform of `node` in the file's world space.
Transform globalTransform(const aiNode* node) {
  Transform t;
  for (; node; node = node->mParent) t = toTransform(node->mTransformation) * t;
  return t;
}

std::optional<Camera> firstCamera(const aiScene& ai, const Transform& xf) {
  if (ai.mNumCameras == 0) return std::nullopt;
  const aiCamera& c = *ai.mCameras[0];
  const Transform t = xf * globalTransform(ai.mRootNode->FindNode(c.mName));
  Camera cam;
  // assimp 5.2 also copies the camera node's translation into mPosition: the node's
  // transform alone places the camera (a glTF camera sits at its node's origin).
  cam.position = t.point(Vec3(0.0f));
  cam.lookAt = cam.position + t.vector(Vec3(c.mLookAt.x, c.mLookAt.y, c.mLookAt.z));
  cam.up = t.vector(Vec3(c.mUp.x, c.mUp.y, c.mUp.z));
  // assimp 5.2 stores glTF's yfov times the aspect ratio as the "horizontal" field of view.
  const float aspect = c.mAspect > 0.0f ? c.mAspect : 1.0f;
  cam.vfovDeg = std::clamp(c.mHorizontalFOV / aspect * 180.0f / kPi, 1.0f, 170.0f);
  cam.width = 512;
  cam.height = std::clamp(static_cast<int>(std::lround(512.0f / aspect)), 1, 16384);
  return cam;
}

}  // namespace

MeshLoadStats loadGltf(const std::string& path, const std::string& field, const Transform& xf,
                       World& world, std::optional<Camera>& camera) {
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, field, std::string("cannot open: ") + std::strerror(errno));
  }
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure);
  if (!ai || !ai->mRootNode || (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    const std::string msg = importer.GetErrorString();
    throw InputError(path, field, "malformed glTF: " + msg.substr(0, 300));
  }
  std::vector<uint32_t> materials;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i)
    materials.push_back(addMaterial(world, gltfMaterial(*ai->mMaterials[i], i, path, world)));
  if (materials.empty())
    materials.push_back(addMaterial(world, Material{"(default)", RGB(0.8f), RGB(0.0f)}));
  MeshLoadStats stats;
  addNode(*ai, *ai->mRootNode, xf, materials, world, stats);
  if (stats.triangles == 0) throw InputError(path, field, "the glTF has no valid triangles");
  if (!camera) camera = firstCamera(*ai, xf);
  return stats;
}

}  // namespace lvox
