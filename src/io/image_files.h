// Writing images through MRPT (private to io/: its headers expose core types only).
#pragma once

#include <string>

namespace mrpt::img {
class CImage;
}

namespace evidential_slam {
namespace io {

class AtomicFiles;

// Stages `img` as `path` in the format of its extension (PNG, PGM) into `files`, checked complete
// once written. False (and a one-line `error`) when it cannot be written.
bool stageImage(const mrpt::img::CImage& img, const std::string& path, AtomicFiles* files,
                std::string* error);

}  // namespace io
}  // namespace evidential_slam
