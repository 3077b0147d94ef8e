// NumPy .npy format 1.0 (read: 1.0, 2.0, 3.0): magic "\x93NUMPY", version 1.0, little-endian uint16
// header length, a Python dict literal padded with spaces and '\n' so the payload starts on a
// 64-byte boundary.
#include "evidential_slam/io/npy.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicLen = 6;

bool writeRaw(std::ostream& out, const char* descr, const void* data, size_t bytes, int rows,
              int cols) {
  if (rows < 0 || cols < 0) return false;
  std::string header = std::string("{'descr': '") + descr +
                       "', 'fortran_order': False, 'shape': (" + std::to_string(rows) + ", " +
                       std::to_string(cols) + "), }";
  const size_t preamble = kMagicLen + 2 + 2;
  const size_t total = ((preamble + header.size() + 1 + 63) / 64) * 64;
  header.append(total - preamble - header.size() - 1, ' ');
  header.push_back('\n');
  const uint16_t len = static_cast<uint16_t>(header.size());
  const char version_and_len[4] = {1, 0, static_cast<char>(len & 0xff),
                                   static_cast<char>(len >> 8)};
  out.write(kMagic, kMagicLen);
  out.write(version_and_len, 4);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  return static_cast<bool>(out);
}

bool littleEndianHost() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

}  // namespace

bool writeNpy(std::ostream& out, const float* data, int rows, int cols) {
  static_assert(sizeof(float) == 4, "float32 expected");
  if (!littleEndianHost()) return false;  // the payload is written as it is in memory
  return writeRaw(out, "<f4", data, sizeof(float) * static_cast<size_t>(rows) * cols, rows, cols);
}

bool writeNpy(std::ostream& out, const uint8_t* data, int rows, int cols) {
  return writeRaw(out, "|u1", data, static_cast<size_t>(rows) * cols, rows, cols);
}

bool writeNpy(const std::string& path, const float* data, int rows, int cols, std::string* error) {
  if (!littleEndianHost()) {
    if (error) *error = "big-endian hosts are not supported by the .npy writer";
    return false;
  }
  if (rows < 0 || cols < 0) {
    if (error) *error = "negative array shape for '" + path + "'";
    return false;
  }
  return writeFileAtomically(
      path, [&](std::ostream& out) { return writeNpy(out, data, rows, cols); }, error);
}

bool writeNpy(const std::string& path, const uint8_t* data, int rows, int cols,
              std::string* error) {
  if (rows < 0 || cols < 0) {
    if (error) *error = "negative array shape for '" + path + "'";
    return false;
  }
  return writeFileAtomically(
      path, [&](std::ostream& out) { return writeNpy(out, data, rows, cols); }, error);
}

size_t NpyArray::elementCount() const {
  size_t n = 1;
  for (size_t d : shape) n *= d;  // readNpy checked that this does not overflow
  return n;
}

std::vector<float> NpyArray::asFloat32() const {
  if (descr != "<f4" || bytes.size() != 4 * elementCount()) return {};
  std::vector<float> out(elementCount());
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

std::vector<uint8_t> NpyArray::asUint8() const {
  if ((descr != "|u1" && descr != "<u1") || bytes.size() != elementCount()) return {};
  return bytes;
}

namespace {

// A small parser for the header's Python dict literal, bounded by the header's length (itself
// bounded): {'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }. No recursion, no regex.
class HeaderParser {
 public:
  explicit HeaderParser(const std::string& text) : s_(text) {}

  bool parse(NpyArray* array, std::string* why) {
    bool have_descr = false, have_order = false, have_shape = false;
    skipSpace();
    if (!eat('{')) return fail("the header is not a dict", why);
    for (;;) {
      skipSpace();
      if (eat('}')) break;
      std::string key;
      if (!quoted(&key)) return fail("a header key is not a quoted string", why);
      skipSpace();
      if (!eat(':')) return fail("no ':' after header key '" + key + "'", why);
      skipSpace();
      if (key == "descr") {
        if (have_descr) return fail("duplicate header key 'descr'", why);
        if (!quoted(&array->descr)) return fail("'descr' is not a quoted string", why);
        have_descr = true;
      } else if (key == "fortran_order") {
        if (have_order) return fail("duplicate header key 'fortran_order'", why);
        if (word("True")) {
          array->fortran_order = true;
        } else if (word("False")) {
          array->fortran_order = false;
        } else {
          return fail("'fortran_order' is not True or False", why);
        }
        have_order = true;
      } else if (key == "shape") {
        if (have_shape) return fail("duplicate header key 'shape'", why);
        if (!tuple(&array->shape, why)) return false;
        have_shape = true;
      } else {
        return fail("unknown header key '" + key + "'", why);
      }
      skipSpace();
      if (eat(',')) continue;
      skipSpace();
      if (eat('}')) break;
      return fail("no ',' or '}' after header key '" + key + "'", why);
    }
    skipSpace();
    if (i_ != s_.size()) return fail("text after the header dict", why);
    if (!have_descr) return fail("no 'descr' in the header", why);
    if (!have_order) return fail("no 'fortran_order' in the header", why);
    if (!have_shape) return fail("no 'shape' in the header", why);
    return true;
  }

 private:
  static bool fail(const std::string& what, std::string* why) {
    *why = what;
    return false;
  }
  void skipSpace() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r'))
      ++i_;
  }
  bool eat(char c) {
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  bool word(const char* w) {
    const size_t n = std::strlen(w);
    if (s_.compare(i_, n, w) != 0) return false;
    i_ += n;
    return true;
  }
  // A '...' or "..." string of printable ASCII without escapes (all numpy writes), at most 32
  // characters: keys and dtype descriptors are short.
  bool quoted(std::string* out) {
    if (i_ >= s_.size() || (s_[i_] != '\'' && s_[i_] != '"')) return false;
    const char q = s_[i_++];
    out->clear();
    while (i_ < s_.size() && s_[i_] != q) {
      const unsigned char c = static_cast<unsigned char>(s_[i_]);
      if (c < 0x20 || c >= 0x7f || c == '\\' || out->size() >= 32) return false;
      out->push_back(static_cast<char>(c));
      ++i_;
    }
    return eat(q);
  }
  // (d0, d1, ...) of non-negative decimal integers, at most kNpyMaxDimensions of them, each at most
  // kNpyMaxExtent.
  bool tuple(std::vector<size_t>* shape, std::string* why) {
    shape->clear();
    if (!eat('(')) return fail("'shape' is not a tuple", why);
    for (;;) {
      skipSpace();
      if (eat(')')) return true;
      if (i_ >= s_.size() || s_[i_] < '0' || s_[i_] > '9') {
        return fail("'shape' holds something other than a non-negative integer", why);
      }
      uint64_t v = 0;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') {
        v = v * 10 + static_cast<uint64_t>(s_[i_++] - '0');
        if (v > kNpyMaxExtent) {
          return fail("a 'shape' dimension exceeds " + std::to_string(kNpyMaxExtent), why);
        }
      }
      if (shape->size() >= kNpyMaxDimensions) {
        return fail("'shape' has more than " + std::to_string(kNpyMaxDimensions) + " dimensions",
                    why);
      }
      shape->push_back(static_cast<size_t>(v));
      skipSpace();
      if (eat(',')) continue;
      skipSpace();
      if (eat(')')) return true;
      return fail("'shape' is not a tuple of integers", why);
    }
  }

  const std::string& s_;
  size_t i_ = 0;
};

size_t itemSize(const std::string& descr) {
  if (descr == "<f4") return 4;
  if (descr == "|u1" || descr == "<u1") return 1;
  return 0;
}

}  // namespace

bool parseNpy(const uint8_t* data, size_t size, NpyArray* array, std::string* why) {
  auto fail = [&](const std::string& w) {
    *why = w;
    return false;
  };
  if (size < kMagicLen + 2 || std::memcmp(data, kMagic, kMagicLen) != 0) {
    return fail("not a .npy file (no \\x93NUMPY magic)");
  }
  const int major = data[kMagicLen];
  size_t pos = kMagicLen + 2;
  uint64_t header_len = 0;
  if (major == 1) {
    if (size < pos + 2) return fail("header length: the file ends early");
    header_len = data[pos] | (uint64_t{data[pos + 1]} << 8);
    pos += 2;
  } else if (major == 2 || major == 3) {
    if (size < pos + 4) return fail("header length: the file ends early");
    header_len = data[pos] | (uint64_t{data[pos + 1]} << 8) | (uint64_t{data[pos + 2]} << 16) |
                 (uint64_t{data[pos + 3]} << 24);
    pos += 4;
  } else {
    return fail("unsupported .npy version " + std::to_string(major));
  }
  if (header_len > kNpyMaxHeaderBytes) {
    return fail("header length " + std::to_string(header_len) + " exceeds " +
                std::to_string(kNpyMaxHeaderBytes) + " bytes");
  }
  if (header_len > size - pos) return fail("header: the file ends early");
  const std::string header(reinterpret_cast<const char*>(data + pos), header_len);
  pos += header_len;
  NpyArray a;
  std::string what;
  if (!HeaderParser(header).parse(&a, &what)) return fail("header: " + what);
  const size_t item = itemSize(a.descr);
  if (item == 0) {
    return fail("'descr': unsupported dtype '" + a.descr + "' (float32 '<f4' or uint8 '|u1')");
  }
  // shape x itemsize, checked, must be exactly what follows the header.
  uint64_t bytes = item;
  for (size_t d : a.shape) {
    if (d != 0 && bytes > std::numeric_limits<uint64_t>::max() / d) {
      return fail("'shape': the array's size overflows");
    }
    bytes *= d;
  }
  const uint64_t payload = size - pos;
  if (a.elementCount() == 0) bytes = 0;
  if (bytes != payload) {
    return fail("'shape': " + std::to_string(bytes) + " bytes of data expected, the file holds " +
                std::to_string(payload));
  }
  a.bytes.assign(data + pos, data + size);
  if (a.fortran_order && a.shape.size() >= 2) {
    if (a.shape.size() > 2) return fail("'fortran_order': True for more than 2 dimensions");
    // Column-major (rows, cols) to row-major.
    const size_t rows = a.shape[0], cols = a.shape[1];
    std::vector<uint8_t> c_order(a.bytes.size());
    for (size_t r = 0; r < rows; ++r) {
      for (size_t c = 0; c < cols; ++c) {
        std::memcpy(&c_order[(r * cols + c) * item], &a.bytes[(c * rows + r) * item], item);
      }
    }
    a.bytes.swap(c_order);
  }
  a.fortran_order = false;  // the bytes are in C order now
  *array = std::move(a);
  return true;
}

bool readNpy(const std::string& path, NpyArray* array, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = quotedPath(path) + ": " + oneLineMessage(why);
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("not a regular file");
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return fail("cannot read its size");
  if (size > kNpyMaxFileBytes) {
    return fail(std::to_string(size) + " bytes exceed the limit of " +
                std::to_string(kNpyMaxFileBytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot open");
  std::vector<uint8_t> data(static_cast<size_t>(size));
  if (!in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(size)) ||
      in.peek() != std::char_traits<char>::eof()) {
    return fail("the file changed while it was read");
  }
  std::string why;
  if (!parseNpy(data.data(), data.size(), array, &why)) return fail(why);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
