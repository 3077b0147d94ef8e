// EvidentialOcTree, its node I/O and the checked reader. See evidential_octree.h.
#include "evidential_slam/io/evidential_octree.h"

#include <octomap/AbstractOcTree.h>
#include <octomap/octomap_types.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <system_error>

#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace io {

static_assert(sizeof(float) == 4, "the file layout stores float32");
static_assert(EvidentialOcTreeNode::payloadBytes(EvidentialLayout::kMasses) == 4 * sizeof(float),
              "layout 1 = 4 floats");
static_assert(EvidentialOcTreeNode::payloadBytes(EvidentialLayout::kMassesAnomaly) ==
                  5 * sizeof(float),
              "layout 2 = 5 floats");

namespace {

constexpr double kBetPClamp = 1e-6;
// Masses may leave [0, 1] and their sum exceed 1 by float rounding (core's own tolerance).
constexpr float kMassTolerance = 1e-5f;

}  // namespace

float occupancyLogOdds(const Cell& cell) {
  const double p = std::clamp(pignistic(cell), kBetPClamp, 1.0 - kBetPClamp);
  return static_cast<float>(std::log(p / (1.0 - p)));
}

bool isValidStoredCell(float occupied, float free, float lambda) {
  if (!std::isfinite(occupied) || !std::isfinite(free) || !std::isfinite(lambda)) return false;
  const auto in_unit = [](float m) { return m >= -kMassTolerance && m <= 1.0f + kMassTolerance; };
  return in_unit(occupied) && in_unit(free) && occupied + free <= 1.0f + kMassTolerance &&
         lambda >= 0.0f;
}

// ---- node ---------------------------------------------------------------------------------------

std::istream& EvidentialOcTreeNode::readData(std::istream& s, EvidentialLayout layout) {
  float v[5] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  s.read(reinterpret_cast<char*>(v), static_cast<std::streamsize>(payloadBytes(layout)));
  if (!s) return s;  // short read: eofbit and failbit are set
  value = v[0];
  // The masses and the anomaly are kept only when valid (cell() rounds them to a grid's storage,
  // which needs finite values).
  if (!std::isfinite(value) || !isValidStoredCell(v[1], v[2], v[3]) || !std::isfinite(v[4]) ||
      v[4] < 0.0f) {
    s.setstate(std::ios::failbit);
    return s;
  }
  occupied_ = v[1];
  free_ = v[2];
  lambda_ = v[3];
  anomaly_ = v[4];
  return s;
}

std::ostream& EvidentialOcTreeNode::writeData(std::ostream& s, EvidentialLayout layout) const {
  const float v[5] = {value, occupied_, free_, lambda_, anomaly_};
  return s.write(reinterpret_cast<const char*>(v),
                 static_cast<std::streamsize>(payloadBytes(layout)));
}

Mass EvidentialOcTreeNode::mass() const {
  // On the unrounded floats (the pair may sum to a hair above 1 within isValidStoredCell's
  // tolerance: m(Θ) is then 0).
  return massFromNormalised(occupied_, free_, lambda_);
}

// ---- tree ---------------------------------------------------------------------------------------

const std::string EvidentialOcTree::kTreeType = "EvidentialOcTree";
const std::string EvidentialOcTree::kAnomalyTreeType = "EvidentialAnomalyOcTree";

const std::string& EvidentialOcTree::treeTypeOf(EvidentialLayout layout) {
  return layout == EvidentialLayout::kMasses ? kTreeType : kAnomalyTreeType;
}

bool EvidentialOcTree::layoutOf(const std::string& tree_type, EvidentialLayout* layout) {
  for (EvidentialLayout l : {EvidentialLayout::kMasses, EvidentialLayout::kMassesAnomaly}) {
    if (tree_type == treeTypeOf(l)) {
      *layout = l;
      return true;
    }
  }
  return false;
}

EvidentialOcTree::StaticMemberInitializer::StaticMemberInitializer() {
  // One prototype per layout, owned by OctoMap's factory for the process.
  for (EvidentialLayout l : {EvidentialLayout::kMasses, EvidentialLayout::kMassesAnomaly}) {
    auto* prototype = new EvidentialOcTree(0.1, l);
    prototype->clearKeyRays();
    AbstractOcTree::registerTreeType(prototype);
  }
}

EvidentialOcTree::StaticMemberInitializer EvidentialOcTree::registration_;

EvidentialOcTree::EvidentialOcTree(double resolution, EvidentialLayout layout)
    : OccupancyOcTreeBase<EvidentialOcTreeNode>(resolution), layout_(layout) {
  registration_.ensureLinking();
}

EvidentialOcTree::~EvidentialOcTree() = default;

EvidentialOcTree* EvidentialOcTree::create() const {
  return new EvidentialOcTree(resolution, layout_);
}

std::string EvidentialOcTree::getTreeType() const { return treeTypeOf(layout_); }

EvidentialOcTreeNode* EvidentialOcTree::setNodeCell(const octomap::OcTreeKey& key, const Cell& cell,
                                                    float anomaly) {
  // setNodeValue creates the path (lazily, no pruning) but clamps the value to OctoMap's
  // clamping thresholds; setCell then stores the exact value with the masses.
  EvidentialOcTreeNode* node = setNodeValue(key, occupancyLogOdds(cell), /*lazy_eval=*/true);
  if (node != nullptr) {
    node->setCell(cell);
    node->setAnomaly(anomaly);
  }
  return node;
}

void EvidentialOcTree::updateInnerNodes() {
  if (root != nullptr) updateInnerNodesRecurs(root, 0);
}

void EvidentialOcTree::updateInnerNodesRecurs(EvidentialOcTreeNode* node, unsigned depth) {
  if (!nodeHasChildren(node)) return;
  const EvidentialOcTreeNode* most_occupied = nullptr;
  float anomaly = 0.0f;
  for (unsigned i = 0; i < 8; ++i) {
    if (!nodeChildExists(node, i)) continue;
    EvidentialOcTreeNode* child = getNodeChild(node, i);
    if (depth + 1 < tree_depth) updateInnerNodesRecurs(child, depth + 1);
    if (most_occupied == nullptr || child->getLogOdds() > most_occupied->getLogOdds()) {
      most_occupied = child;
    }
    anomaly = std::max(anomaly, child->anomaly());
  }
  node->copyData(*most_occupied);
  node->setAnomaly(anomaly);
}

std::ostream& EvidentialOcTree::writeData(std::ostream& s) const {
  if (root != nullptr) writeNodesRecurs(root, s);
  return s;
}

void EvidentialOcTree::writeNodesRecurs(const EvidentialOcTreeNode* node, std::ostream& s) const {
  // OctoMap's own order (OcTreeBaseImpl::writeNodesRecurs): payload, child byte, children.
  node->writeData(s, layout_);
  unsigned char children = 0;
  for (unsigned i = 0; i < 8; ++i) {
    if (nodeChildExists(node, i)) children |= static_cast<unsigned char>(1u << i);
  }
  s.write(reinterpret_cast<const char*>(&children), 1);
  for (unsigned i = 0; i < 8; ++i) {
    if (children & (1u << i)) writeNodesRecurs(getNodeChild(node, i), s);
  }
}

bool EvidentialOcTree::readNodesRecurs(EvidentialOcTreeNode* node, unsigned depth, std::istream& s,
                                       uint64_t max_nodes, uint64_t* count, std::string* error) {
  if (!node->readData(s, layout_)) {
    if (s.eof()) {
      *error = "truncated: the data ends inside node " + std::to_string(*count);
    } else {
      // (The node keeps none of the rejected values: readData stores only valid ones.)
      *error = "node " + std::to_string(*count) +
               " holds values no grid can hold (not finite, a mass outside [0, 1], m~(o) + m~(e) "
               "above 1, or a negative lambda or anomaly)";
    }
    return false;
  }
  unsigned char children = 0;
  s.read(reinterpret_cast<char*>(&children), 1);
  if (!s) {
    *error = "truncated: the data ends after node " + std::to_string(*count);
    return false;
  }
  if (children != 0 && depth >= tree_depth) {
    *error = "node " + std::to_string(*count) + " at the finest level (depth " +
             std::to_string(tree_depth) + ") claims children";
    return false;
  }
  for (unsigned i = 0; i < 8; ++i) {
    if ((children & (1u << i)) == 0) continue;
    if (*count >= max_nodes) {
      *error = "the data holds more nodes than the " + std::to_string(max_nodes) +
               " the header announces";
      return false;
    }
    ++*count;
    if (!readNodesRecurs(createNodeChild(node, i), depth + 1, s, max_nodes, count, error)) {
      return false;
    }
  }
  return true;
}

bool EvidentialOcTree::readNodes(std::istream& s, uint64_t expected_nodes, std::string* error) {
  std::string why;
  clear();
  if (expected_nodes > 0) {
    root = new EvidentialOcTreeNode();
    tree_size = 1;
    size_changed = true;
    uint64_t count = 1;
    if (!readNodesRecurs(root, 0, s, expected_nodes, &count, &why)) {
      clear();
      if (error) *error = why;
      return false;
    }
    tree_size = count;
    if (count != expected_nodes) {
      why = "the header announces " + std::to_string(expected_nodes) + " nodes, the data holds " +
            std::to_string(count);
    }
  }
  if (why.empty() && s.peek() != std::char_traits<char>::eof()) {
    why = expected_nodes == 0 ? "the header announces an empty tree but data follows"
                              : "unexpected bytes after the last node";
  }
  if (!why.empty()) {
    clear();
    if (error) *error = why;
    return false;
  }
  return true;
}

std::istream& EvidentialOcTree::readData(std::istream& s) {
  if (root != nullptr) {
    OCTOMAP_ERROR_STR("Trying to read into an existing tree.");
    s.setstate(std::ios::failbit);
    return s;
  }
  root = new EvidentialOcTreeNode();
  tree_size = 1;
  size_changed = true;
  uint64_t count = 1;
  std::string why;
  if (!readNodesRecurs(root, 0, s, std::numeric_limits<uint64_t>::max(), &count, &why)) {
    clear();
    OCTOMAP_ERROR_STR("Error reading " << kTreeType << ": " << why);
    s.setstate(std::ios::failbit);
    return s;
  }
  tree_size = count;
  return s;
}

// ---- reader -------------------------------------------------------------------------------------

namespace {

constexpr size_t kMaxHeaderLine = 1024;
constexpr int kMaxHeaderLines = 256;
constexpr double kMinResolution = 1e-6;  // m; keeps 1 / resolution and the key math finite
constexpr double kMaxResolution = 1e6;
const std::string kOtMagic = "# Octomap OcTree file";
const std::string kBtMagic = "# Octomap OcTree binary file";

enum class Line { kOk, kEnd, kTooLong };

// One header line without its '\n'; kEnd at end of stream before any character.
Line readLine(std::istream& in, std::string* line) {
  line->clear();
  bool any = false;
  for (int c = in.get(); c != std::char_traits<char>::eof(); c = in.get()) {
    any = true;
    if (c == '\n') return Line::kOk;
    if (line->size() >= kMaxHeaderLine) return Line::kTooLong;
    line->push_back(static_cast<char>(c));
  }
  return any ? Line::kOk : Line::kEnd;
}

// A header word safe to print: printable ASCII only, at most 40 characters.
std::string printable(const std::string& word) {
  std::string out;
  for (char c : word) {
    if (out.size() >= 40) return out + "...";
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  return out;
}

struct Header {
  std::string id;
  EvidentialLayout layout = kLatestEvidentialLayout;
  bool has_size = false, has_res = false;
  uint64_t size = 0;
  double res = 0.0;
};

// OctoMap's header: the magic line, then `key value` lines (id, size, res), '#' comments, and
// `data`, after which the binary node data starts. Unknown keys are skipped, as OctoMap does.
bool readHeader(std::istream& in, Header* h, std::string* why) {
  std::string line;
  const Line first = readLine(in, &line);
  if (first == Line::kEnd) {
    *why = "empty file";
    return false;
  }
  if (line.compare(0, kBtMagic.size(), kBtMagic) == 0) {
    *why = "a binary OctoMap file (.bt: occupied/free only, no masses), not an " +
           EvidentialOcTree::kTreeType + " .ot file";
    return false;
  }
  if (first == Line::kTooLong || line.compare(0, kOtMagic.size(), kOtMagic) != 0) {
    *why = "not an OctoMap .ot file (the first line is not '" + kOtMagic + "')";
    return false;
  }
  for (int n = 0; n < kMaxHeaderLines; ++n) {
    const Line status = readLine(in, &line);
    if (status == Line::kEnd) {
      *why = "truncated header: no 'data' line";
      return false;
    }
    if (status == Line::kTooLong) {
      *why = "corrupt header: a line longer than " + std::to_string(kMaxHeaderLine) + " bytes";
      return false;
    }
    const size_t k0 = line.find_first_not_of(" \t\r");
    if (k0 == std::string::npos || line[k0] == '#') continue;
    const size_t k1 = std::min(line.find_first_of(" \t\r", k0), line.size());
    const std::string key = line.substr(k0, k1 - k0);
    const size_t v0 = std::min(line.find_first_not_of(" \t\r", k1), line.size());
    const size_t v1 = std::min(line.find_first_of(" \t\r", v0), line.size());
    const std::string value = line.substr(v0, v1 - v0);
    if (key == "data") {
      if (h->id.empty()) {
        *why = "corrupt header: no tree 'id'";
      } else if (!EvidentialOcTree::layoutOf(h->id, &h->layout)) {
        *why = "holds an OctoMap '" + printable(h->id) + "', not an '" +
               EvidentialOcTree::kAnomalyTreeType + "' or '" + EvidentialOcTree::kTreeType +
               "' (no evidential masses)";
      } else if (!h->has_res) {
        *why = "corrupt header: no 'res'";
      } else if (!h->has_size) {
        *why = "corrupt header: no 'size'";
      } else {
        return true;
      }
      return false;
    }
    if (key == "id") {
      h->id = value;
    } else if (key == "size") {
      const auto r = std::from_chars(value.data(), value.data() + value.size(), h->size);
      if (r.ec != std::errc() || r.ptr != value.data() + value.size() || value.empty()) {
        *why = "corrupt header: size '" + printable(value) + "' is not a node count";
        return false;
      }
      h->has_size = true;
    } else if (key == "res") {
      const auto r = std::from_chars(value.data(), value.data() + value.size(), h->res);
      if (r.ec != std::errc() || r.ptr != value.data() + value.size() || value.empty() ||
          !(h->res >= kMinResolution && h->res <= kMaxResolution)) {
        *why = "corrupt header: resolution '" + printable(value) + "' is not in [1e-6, 1e6] m";
        return false;
      }
      h->has_res = true;
    }
  }
  *why =
      "corrupt header: no 'data' line in the first " + std::to_string(kMaxHeaderLines) + " lines";
  return false;
}

}  // namespace

bool readEvidentialOctree(std::istream& in, const std::string& name,
                          std::unique_ptr<EvidentialOcTree>* tree, std::string* error) {
  tree->reset();
  const auto fail = [&](const std::string& why) {
    if (error) *error = "'" + name + "': " + why;
    return false;
  };
  try {
    Header header;
    std::string why;
    if (!readHeader(in, &header, &why)) return fail(why);
    // The factory creates the tree from the header's id, as AbstractOcTree::read does; the id was
    // checked above, so no other tree type's (unchecked) reader runs on these bytes.
    std::unique_ptr<octomap::AbstractOcTree> created(
        octomap::AbstractOcTree::createTree(header.id, header.res));
    auto* evidential = dynamic_cast<EvidentialOcTree*>(created.get());
    if (evidential == nullptr || evidential->layout() != header.layout) {
      return fail(header.id +
                  " is not registered with OctoMap's tree factory (library not loaded?)");
    }
    created.release();
    std::unique_ptr<EvidentialOcTree> result(evidential);
    if (!result->readNodes(in, header.size, &why)) return fail(why);
    *tree = std::move(result);
    return true;
  } catch (const std::bad_alloc&) {
    return fail("out of memory while reading");
  } catch (const std::exception& e) {
    return fail(std::string("read error: ") + e.what());
  }
}

bool readEvidentialOctree(const std::string& path, std::unique_ptr<EvidentialOcTree>* tree,
                          std::string* error) {
  tree->reset();
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) {
    if (error) *error = "'" + path + "' does not exist";
    return false;
  }
  if (fs::is_directory(status)) {
    if (error) *error = "'" + path + "' is a directory";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (error) *error = "cannot open '" + path + "'";
    return false;
  }
  return readEvidentialOctree(in, path, tree, error);
}

}  // namespace io
}  // namespace evidential_slam
