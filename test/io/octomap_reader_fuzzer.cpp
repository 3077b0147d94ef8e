// libFuzzer target for readEvidentialOctree (built with clang by cmake/OctomapTargets.cmake, run by
// test_octomap_fuzz). Besides "no crash, no leak, no undefined behaviour" under ASan/UBSan, a file
// the reader accepts must hold only valid masses, and writing the tree's node data back must give
// exactly the bytes the file ended with (the reader accepts no trailing bytes) in the file's own
// layout (1: masses, 2: masses and anomaly).
// ES_FUZZ_EXPECT_VALID=1 makes any rejected input abort: the test uses it to check that its valid
// seeds are read by this build.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>

#include "evidential_slam/io/evidential_octree.h"

namespace {

namespace io = evidential_slam::io;

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz invariant broken: %s %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool expect_valid = [] {
    const char* v = std::getenv("ES_FUZZ_EXPECT_VALID");
    return v != nullptr && std::strcmp(v, "1") == 0;
  }();
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::istringstream in(bytes);
  std::unique_ptr<io::EvidentialOcTree> tree;
  std::string error;
  const bool ok = io::readEvidentialOctree(in, "fuzz input", &tree, &error);
  if (!ok) {
    if (tree) die("tree returned with an error:", error);
    if (error.empty() || error.find('\n') != std::string::npos) die("bad error message:", error);
    if (expect_valid) die("valid seed rejected:", error);
    return 0;
  }
  if (!tree) die("success without a tree", "");
  size_t nodes = 0;
  for (auto it = tree->begin_tree(), end = tree->end_tree(); it != end; ++it) {
    ++nodes;
    const evidential_slam::Cell& c = it->cell();
    if (!io::isValidStoredCell(c.occupied(), c.free(), c.lambda())) {
      die("invalid cell accepted", "");
    }
    if (!(it->anomaly() >= 0.0f) || !std::isfinite(it->anomaly())) {
      die("invalid anomaly accepted", "");
    }
    if (tree->layout() == io::EvidentialLayout::kMasses && it->anomaly() != 0.0f) {
      die("an anomaly in a layout-1 file", "");
    }
    if (it.getDepth() > tree->getTreeDepth()) die("node below the finest level", "");
  }
  if (nodes != tree->size()) die("size() disagrees with the nodes", "");
  std::ostringstream out;
  tree->writeData(out);
  const std::string written = out.str();
  if (written.size() > bytes.size() ||
      bytes.compare(bytes.size() - written.size(), written.size(), written) != 0) {
    die("node data does not round-trip", "");
  }
  return 0;
}
