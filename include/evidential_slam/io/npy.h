// Minimal NumPy .npy (format 1.0) writer and reader for 2-D C-order arrays of float32 and uint8,
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

// Reads a version 1.0/2.0 .npy file. False (and `error`) on a bad magic, header or size.
bool readNpy(const std::string& path, NpyArray* array, std::string* error);

}  // namespace io
}  // namespace evidential_slam
