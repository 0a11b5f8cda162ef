#pragma once
// Every channel of an OpenEXR file, not only R, G, B: renders may carry AOV layers
// ("albedo.R", "depth.Z", ...), and `lvox report` shows whatever a file holds. Channel
// names follow the EXR convention LAYER.CHANNEL; the layer of "R" is "" (the colour).
#include <optional>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/image_io.h"

namespace lvox {

struct ExrChannels {
  int width = 0;
  int height = 0;
  std::vector<std::string> names;          // in display order (see sortChannelNames)
  std::vector<std::vector<float>> planes;  // one per name, width * height, top row first
  ImageMetadata metadata;                  // string attributes of the header

  // The plane of a channel, nullptr when the file has no channel of that name.
  const std::vector<float>* find(const std::string& name) const;
};

// Reads every channel as float32 (half and uint channels are converted). Throws
// InputError on a missing, corrupt, deep or subsampled file.
ExrChannels readExrChannels(const std::string& path);

// Writes every channel as float32, ZIP-compressed, published atomically; NaN and infinite
// values are written as 0.
void writeExrChannels(const std::string& path, const ExrChannels& channels);

// The layer of a channel name: everything before the last '.', "" when there is none.
std::string channelLayer(const std::string& name);

// Orders names by layer ("" first), then R, G, B, A, Y, Z, then the rest alphabetically,
// so a layer reads as colour first whatever order the file stored them in.
void sortChannelNames(std::vector<std::string>& names);

// The colour of the file as `readExr` would give it: R, G, B of the default layer, or Y
// as grey; nullopt when the file has neither (an AOV-only file).
std::optional<Image> colourImage(const ExrChannels& channels);

}  // namespace lvox
