#pragma once
// A check of an OpenEXR file's headers before OpenEXR reads them. OpenEXR 3.1 allocates
// what an attribute's size field says before reading its bytes (a 392-byte file made it
// allocate 1.8 GB for one string attribute), and sizes its line offset table from the data
// window (found by fuzzing, issue 16). This walks every attribute of every part's header
// and refuses sizes beyond the end of the file, and scanline data windows with more rows
// than the file has room for offsets.
#include <string>

namespace lvox {

// Throws InputError(path, "", "not a readable OpenEXR file: ...") on the first problem.
void precheckExrFile(const std::string& path);

}  // namespace lvox
