// `lvox merge A.exr B.exr ... -o OUT.exr`: joins chunks of one render (same scene, mode
// and seed, disjoint sample ranges from --first-sample) into one image weighted by spp,
// so a long reference can be built across runs without losing finished work.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "src/app/commands.h"
#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/exr_channels.h"
#include "src/core/image_io.h"
#include "src/render/render_settings.h"

namespace lvox {
namespace {

struct MergeFlags {
  std::vector<std::string> inputs;
  std::string output;
  uint64_t expectSpp = 0;  // 0: no expectation
};

struct Chunk {
  std::string path;
  Image image;
  uint64_t first = 0;
  uint64_t spp = 0;
  ExrChannels channels;  // every channel, read when the chunk has AOV layers
};

uint64_t numberAttribute(const ImageMetadata& meta, const std::string& key,
                         const std::string& path) {
  auto it = meta.find(key);
  if (it == meta.end())
    throw InputError(path, key, "missing: not an lvox render (no sample count)");
  try {
    return std::stoull(it->second);
  } catch (const std::exception&) {
    throw InputError(path, key, "is not a number: '" + it->second + "'");
  }
}

// Chunks of one image share every setting that changes it: the scene and its files, the
// seed and mode, every setting of the render and the volume integrator, and in the pcb
// modes the point cloud's. (Chunks of MC or direct renders made before lvox stopped
// recording the cloud's settings there still carry them; they change nothing.)
bool sharedSetting(const std::string& key, bool pointBased) {
  for (const char* exact :
       {"lvox.seed", "lvox.mode", "lvox.scene", "lvox.scene_hash", "lvox.layers"})
    if (key == exact) return true;
  for (const char* prefix : {"lvox.render.", "lvox.volume_integrator."})
    if (key.rfind(prefix, 0) == 0) return true;
  return pointBased && key.rfind("lvox.pointcloud.", 0) == 0;
}

bool pointBasedChunk(const ImageMetadata& meta, const std::string& path) {
  const auto it = meta.find("lvox.mode");
  return it != meta.end() && isPointBased(parseMode(it->second, path, "lvox.mode"));
}

void requireSameSettings(const ImageMetadata& meta, const ImageMetadata& first,
                         const std::string& path, const std::string& firstPath) {
  // lvox.mode is itself shared: a pcb chunk beside an MC one is refused by it.
  const bool pointBased = pointBasedChunk(first, firstPath) || pointBasedChunk(meta, path);
  std::map<std::string, std::pair<std::string, std::string>> keys;
  for (const auto& [key, value] : first)
    if (sharedSetting(key, pointBased)) keys[key].first = value;
  for (const auto& [key, value] : meta)
    if (sharedSetting(key, pointBased)) keys[key].second = value;
  for (const auto& [key, values] : keys)
    if (values.first != values.second)
      throw InputError(path, key,
                       "differs from " + firstPath + " ('" + values.second + "' vs '" +
                           values.first + "'): chunks of one render share every setting");
}

struct SampleRange {
  uint64_t first = 0, end = 0;
};

// The ranges of [from, to) that no chunk holds (chunks sorted by first sample, disjoint).
std::vector<SampleRange> missingRanges(const std::vector<Chunk>& chunks, uint64_t from,
                                       uint64_t to) {
  std::vector<SampleRange> missing;
  uint64_t next = from;
  for (const Chunk& c : chunks) {
    if (c.first > next) missing.push_back({next, std::min(c.first, to)});
    next = std::max(next, c.first + c.spp);
  }
  if (next < to) missing.push_back({next, to});
  return missing;
}

// "[4, 8) (--first-sample 4 --spp 4), ...": what to render again.
std::string describe(const std::vector<SampleRange>& ranges) {
  std::string text;
  for (const SampleRange& r : ranges)
    text += (text.empty() ? "" : ", ") +
            ("[" + std::to_string(r.first) + ", " + std::to_string(r.end) + ") (--first-sample " +
             std::to_string(r.first) + " --spp " + std::to_string(r.end - r.first) + ")");
  return text;
}

// A chunk that never arrived (a cluster task that died) leaves a gap: with --expect-spp
// the merge refuses and names the ranges to render again; without it, the image of the
// samples present is valid, and the gaps are a warning.
void checkCoverage(const std::vector<Chunk>& chunks, const MergeFlags& f) {
  if (f.expectSpp == 0) {
    const auto gaps =
        missingRanges(chunks, chunks.front().first, chunks.back().first + chunks.back().spp);
    if (!gaps.empty())
      std::cerr << "lvox: warning: no chunk holds samples " << describe(gaps)
                << ": merging the samples present\n";
    return;
  }
  for (const Chunk& c : chunks)
    if (c.first + c.spp > f.expectSpp)
      throw InputError(c.path, "lvox.first_sample",
                       "holds samples up to " + std::to_string(c.first + c.spp) +
                           ", beyond --expect-spp " + std::to_string(f.expectSpp));
  const auto missing = missingRanges(chunks, 0, f.expectSpp);
  if (!missing.empty())
    throw InputError("--expect-spp", "",
                     "samples " + describe(missing) +
                         " are missing: render them, then merge again (nothing written)");
}

// A channel of a chunk, which its lvox.layers promise.
const std::vector<float>& channel(const Chunk& c, const std::string& name) {
  const std::vector<float>* plane = c.channels.find(name);
  if (!plane) throw InputError(c.path, name, "missing, though the chunk's lvox.layers name it");
  return *plane;
}

// The variance of one beauty channel's mean over all chunks, from each chunk's mean m_i
// and variance of the mean v_i over n_i samples: sum x^2 = n_i (n_i - 1) v_i + n_i m_i^2.
std::vector<float> mergedVariance(const std::vector<Chunk>& chunks, const std::string& name, int c,
                                  uint64_t total) {
  const size_t n = chunks[0].image.pixels.size();
  std::vector<double> sum(n, 0.0), squares(n, 0.0);
  for (const Chunk& k : chunks) {
    const std::vector<float>& v = channel(k, name);
    const double ni = static_cast<double>(k.spp);
    for (size_t i = 0; i < n; ++i) {
      const double m = k.image.pixels[i][c];
      sum[i] += ni * m;
      squares[i] += ni * (ni - 1.0) * v[i] + ni * m * m;
    }
  }
  std::vector<float> out(n, 0.0f);
  const double nt = static_cast<double>(total);
  if (total < 2) return out;
  for (size_t i = 0; i < n; ++i) {
    const double mean = sum[i] / nt;
    out[i] = static_cast<float>(std::max(0.0, (squares[i] - nt * mean * mean) / (nt - 1.0)) / nt);
  }
  return out;
}

// Each layer channel of the merged image: means weighted by samples; depth by the samples
// that hit a surface (spp x coverage); the variance recombined from the chunks' moments.
std::vector<ExtraChannel> mergedLayers(const std::vector<Chunk>& chunks, uint64_t total) {
  std::vector<ExtraChannel> out;
  const size_t n = chunks[0].image.pixels.size();
  for (const std::string& name : chunks[0].channels.names) {
    if (channelLayer(name).empty()) continue;  // the beauty
    const std::string layer = channelLayer(name);
    if (layer == "variance") {
      const int c = name.back() == 'R' ? 0 : name.back() == 'G' ? 1 : 2;
      out.push_back({name, mergedVariance(chunks, name, c, total)});
      continue;
    }
    std::vector<double> sum(n, 0.0), weight(n, 0.0);
    for (const Chunk& k : chunks) {
      const std::vector<float>& v = channel(k, name);
      const std::vector<float>* coverage = layer == "depth" ? &channel(k, "coverage.Y") : nullptr;
      for (size_t i = 0; i < n; ++i) {
        const double w = static_cast<double>(k.spp) * (coverage ? (*coverage)[i] : 1.0f);
        sum[i] += w * v[i];
        weight[i] += w;
      }
    }
    ExtraChannel merged{name, std::vector<float>(n, 0.0f)};
    for (size_t i = 0; i < n; ++i)
      if (weight[i] > 0.0) merged.values[i] = static_cast<float>(sum[i] / weight[i]);
    out.push_back(std::move(merged));
  }
  return out;
}

int runMerge(const MergeFlags& f) {
  if (std::filesystem::path(f.output).extension() != ".exr")
    throw InputError(f.output, "--output", "must end in .exr");
  checkOutputPath(f.output, "--output", f.inputs);
  std::vector<Chunk> chunks;
  ImageMetadata first;
  for (const std::string& path : f.inputs) {
    ImageMetadata meta;
    Chunk c{path, readExr(path, &meta), 0, 0, {}};
    c.first = numberAttribute(meta, "lvox.first_sample", path);
    c.spp = numberAttribute(meta, "lvox.spp", path);
    if (c.spp == 0) throw InputError(path, "lvox.spp", "is 0");
    if (meta.count("lvox.layers")) c.channels = readExrChannels(path);
    if (chunks.empty()) {
      first = meta;
    } else {
      requireSameSettings(meta, first, path, f.inputs.front());
      if (c.image.width != chunks[0].image.width || c.image.height != chunks[0].image.height)
        throw InputError(path, "", "has a different size than " + f.inputs.front());
    }
    chunks.push_back(std::move(c));
  }
  std::sort(chunks.begin(), chunks.end(),
            [](const Chunk& a, const Chunk& b) { return a.first < b.first; });
  for (size_t i = 1; i < chunks.size(); ++i)
    if (chunks[i].first < chunks[i - 1].first + chunks[i - 1].spp)
      throw InputError(chunks[i].path, "lvox.first_sample",
                       "overlaps the samples of " + chunks[i - 1].path +
                           " (the same samples twice would not be independent)");
  checkCoverage(chunks, f);
  Image sum(chunks[0].image.width, chunks[0].image.height);
  uint64_t total = 0;
  for (const Chunk& c : chunks) {
    for (size_t i = 0; i < sum.pixels.size(); ++i)
      sum.pixels[i] += c.image.pixels[i] * static_cast<float>(c.spp);
    total += c.spp;
  }
  for (RGB& p : sum.pixels) p /= static_cast<float>(total);
  ImageMetadata out = first;
  out["lvox.spp"] = std::to_string(total);
  out["lvox.first_sample"] = std::to_string(chunks[0].first);
  out["lvox.merged_from"] = std::to_string(chunks.size());
  writeExr(f.output, sum, false, out, nullptr, mergedLayers(chunks, total));
  std::cerr << "lvox: merged " << chunks.size() << " chunks, " << total << " spp -> " << f.output
            << "\n";
  return 0;
}

}  // namespace

void addMergeCommand(CLI::App& app, int& exitCode) {
  auto flags = std::make_shared<MergeFlags>();
  CLI::App* cmd = app.add_subcommand("merge", "Merge chunks of one render, weighted by spp");
  cmd->add_option("inputs", flags->inputs, "Chunk EXRs written by lvox render")->required();
  cmd->add_option("-o,--output", flags->output, "Merged EXR")->required();
  cmd->add_option("--expect-spp", flags->expectSpp,
                  "The chunks must hold samples [0, N): otherwise name the missing ranges and "
                  "write nothing")
      ->check(CLI::PositiveNumber);
  cmd->callback([flags, &exitCode]() { exitCode = runMerge(*flags); });
}

}  // namespace lvox
