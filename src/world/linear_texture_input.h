#pragma once
// Integer (sRGB-encoded) texture images handed to OpenImageIO's TextureSystem decoded to
// linear light, as half floats, so that everything the TextureSystem does with them (the
// mip levels it makes, the bilinear and trilinear blends, the footprint filter) averages
// light and not its encoding. Read as they are, an 8-bit image's filtered lookup decodes
// the mean of the encoded texels, which is darker than the mean of the decoded ones: 0.214
// against 0.5 on a checker of black and white texels, 0.8 % of Sponza's image at 256 x 256
// (docs/pcb.md, "Textures in linear light"). Only surface_textures.cpp includes this; it
// hides OpenImageIO from the rest.
#include <string>

namespace lvox {

// Registers `path` with OpenImageIO's shared ImageCache (the TextureSystem's), to be read
// from disk afresh: with `decodeColour`, an integer image through the decoding reader (its
// colour channels decoded from sRGB; alpha, a cut-out mask's coverage, kept as stored);
// otherwise by OpenImageIO's own reader, as stored (float images hold light already, and a
// mask's coverage is no light). False, with OpenImageIO's error, if the cache refused it.
bool registerTexture(const std::string& path, bool decodeColour);

// The sRGB transfer function's decode, of a value in [0, 1] (clamped): the one the reader
// applies.
float srgbToLinear(float encoded);

// The attribute (1) of the spec of an image the decoding reader decoded.
inline constexpr const char* kDecodedAttribute = "lvox:decoded";

}  // namespace lvox
