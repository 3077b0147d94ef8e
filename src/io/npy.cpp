// NumPy .npy format 1.0: magic "\x93NUMPY", version 1.0, little-endian uint16 header length, a
// Python dict literal padded with spaces and '\n' so the payload starts on a 64-byte boundary.
#include "evidential_slam/io/npy.h"

#include <cstring>
#include <fstream>
#include <regex>

#include "evidential_slam/io/atomic_files.h"

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
  for (size_t d : shape) n *= d;
  return n;
}

std::vector<float> NpyArray::asFloat32() const {
  if (descr != "<f4" || bytes.size() != 4 * elementCount()) return {};
  std::vector<float> out(elementCount());
  std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

std::vector<uint8_t> NpyArray::asUint8() const {
  if ((descr != "|u1" && descr != "<u1") || bytes.size() != elementCount()) return {};
  return bytes;
}

bool readNpy(const std::string& path, NpyArray* array, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = "'" + path + "': " + why;
    return false;
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot open");
  char pre[10];
  if (!in.read(pre, 8) || std::memcmp(pre, kMagic, kMagicLen) != 0) return fail("not a .npy file");
  const int major = static_cast<uint8_t>(pre[6]);
  size_t header_len = 0;
  if (major == 1) {
    if (!in.read(pre + 8, 2)) return fail("short header");
    header_len =
        static_cast<uint8_t>(pre[8]) | (static_cast<size_t>(static_cast<uint8_t>(pre[9])) << 8);
  } else if (major == 2 || major == 3) {
    unsigned char l[4];
    if (!in.read(reinterpret_cast<char*>(l), 4)) return fail("short header");
    header_len =
        l[0] | (l[1] << 8) | (static_cast<size_t>(l[2]) << 16) | (static_cast<size_t>(l[3]) << 24);
  } else {
    return fail("unsupported .npy version " + std::to_string(major));
  }
  std::string header(header_len, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(header_len))) {
    return fail("short header");
  }
  std::smatch m;
  if (!std::regex_search(header, m, std::regex("'descr':\\s*'([^']*)'"))) {
    return fail("no descr in header");
  }
  *array = NpyArray();
  array->descr = m[1];
  if (!std::regex_search(header, m, std::regex("'fortran_order':\\s*(True|False)"))) {
    return fail("no fortran_order in header");
  }
  array->fortran_order = m[1] == "True";
  if (!std::regex_search(header, m, std::regex("'shape':\\s*\\(([^)]*)\\)"))) {
    return fail("no shape in header");
  }
  const std::string dims = m[1];
  const std::regex number("\\d+");
  for (auto it = std::sregex_iterator(dims.begin(), dims.end(), number);
       it != std::sregex_iterator(); ++it) {
    array->shape.push_back(std::stoul(it->str()));
  }
  size_t item = 0;
  if (array->descr.size() >= 3) item = std::stoul(array->descr.substr(2));
  if (item == 0) return fail("unsupported dtype '" + array->descr + "'");
  const size_t bytes = item * array->elementCount();
  array->bytes.resize(bytes);
  if (!in.read(reinterpret_cast<char*>(array->bytes.data()), static_cast<std::streamsize>(bytes))) {
    return fail("payload shorter than its shape");
  }
  if (in.peek() != std::char_traits<char>::eof()) return fail("payload longer than its shape");
  return true;
}

}  // namespace io
}  // namespace evidential_slam
