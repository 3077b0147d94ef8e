// Minimal NumPy .npy writer (format 1.0) and bounded reader for arrays of float32 and uint8,
// so every map layer can be loaded losslessly with numpy.load(). Only the header is ours; the
// payload is the raw little-endian array.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace evidential_slam {
namespace io {

// Writes a (rows, cols) array, row-major: element (r, c) is data[r * cols + c]. The file is
// replaced only once complete (atomic_files.h).
bool writeNpy(const std::string& path, const float* data, int rows, int cols, std::string* error);
bool writeNpy(const std::string& path, const uint8_t* data, int rows, int cols, std::string* error);
// The same into a stream (false on a negative shape or a stream error).
bool writeNpy(std::ostream& out, const float* data, int rows, int cols);
bool writeNpy(std::ostream& out, const uint8_t* data, int rows, int cols);

// What readNpy found: dtype descriptor ('<f4', '|u1', ...), shape and the raw payload bytes.
struct NpyArray {
  std::string descr;
  bool fortran_order = false;
  std::vector<size_t> shape;
  std::vector<uint8_t> bytes;

  size_t elementCount() const;
  // Payload as float32 / uint8; empty when the dtype does not match.
  std::vector<float> asFloat32() const;
  std::vector<uint8_t> asUint8() const;
};

// What the reader accepts: headers, dimensions and extents bounded before anything is allocated;
// the payload must be exactly shape x itemsize (checked arithmetic) bytes, so what is allocated
// is what the file holds, itself bounded.
constexpr uint64_t kNpyMaxHeaderBytes = 65536;  // numpy writes < 100 for 2-D arrays
constexpr size_t kNpyMaxDimensions = 8;
constexpr uint64_t kNpyMaxExtent = uint64_t{1} << 24;     // per dimension
constexpr uint64_t kNpyMaxFileBytes = uint64_t{1} << 32;  // 4 GiB

// Reads the bytes of a version 1.0/2.0/3.0 .npy file of dtype float32 ('<f4') or uint8 ('|u1',
// '<u1'); a 2-D Fortran-order array is returned in C order (fortran_order false). False and a
// one-line `why` naming the field on a bad magic, version, header, dtype or size.
bool parseNpy(const uint8_t* data, size_t size, NpyArray* array, std::string* why);

// parseNpy on the file at `path`; the one-line `error` starts with the quoted path.
bool readNpy(const std::string& path, NpyArray* array, std::string* error);

}  // namespace io
}  // namespace evidential_slam
