// Which build this is, baked in at build time (cmake/BuildInfo.cmake): the package version and
// `git describe --always --dirty` of the source tree, e.g. "evidential_slam 0.1.0 (git 720ab38)".
// Files record it as their provenance.
#pragma once

#include <string>

namespace evidential_slam {
namespace io {

const std::string& buildVersion();

}  // namespace io
}  // namespace evidential_slam
