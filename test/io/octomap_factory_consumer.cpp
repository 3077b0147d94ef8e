// A third party's view of an evidential .ot file: only OctoMap's factory (AbstractOcTree::read)
// and a dynamic_cast to the library's tree type, nothing else from evidential_slam. Run by
// test_octomap: it fails if Debian's --as-needed linking dropped the library and with it the
// tree's registration. Prints the tree type, node count, and the masses and anomaly of the first
// leaf (the anomaly is 0 in a layout-1 file).
#include <cstdio>
#include <memory>

#include "evidential_slam/io/evidential_octree.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE.evidential.ot\n", argv[0]);
    return 1;
  }
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(argv[1]));
  if (!tree) {
    std::fprintf(stderr, "error: OctoMap could not read '%s'\n", argv[1]);
    return 2;
  }
  const auto* evidential = dynamic_cast<const evidential_slam::io::EvidentialOcTree*>(tree.get());
  if (evidential == nullptr) {
    std::fprintf(stderr, "error: '%s' was read as a %s\n", argv[1], tree->getTreeType().c_str());
    return 3;
  }
  std::printf("type %s nodes %zu\n", evidential->getTreeType().c_str(), evidential->size());
  const auto leaf = evidential->begin_leafs();
  if (leaf != evidential->end_leafs()) {
    const evidential_slam::Cell& c = leaf->cell();
    std::printf("first leaf m~(o) %.9g m~(e) %.9g lambda %.9g anomaly %.9g\n", c.occupied(),
                c.free(), c.lambda(), leaf->anomaly());
  }
  return 0;
}
