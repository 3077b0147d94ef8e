// Error text fit for a user's terminal: one line, printable, short. Exception texts from MRPT carry
// a banner, a location and a call stack; names and lines read from a file may hold any byte.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace evidential_slam {
namespace io {

// The message of an exception text on one line: MRPT's "Message:" part when there is one (without
// its location and call stack), else the first non-empty line; whitespace runs squeezed to one
// space, bytes outside printable ASCII shown as '?', cut to `max_chars` ("..." marks the cut).
// "(no message)" when nothing is left.
std::string oneLineMessage(const std::string& what, size_t max_chars = 160);

// `text` (a name or a line read from a file) in single quotes for a one-line message: printable
// ASCII as is, other bytes as \xNN, cut to `max_chars` of the original ("..." marks the cut).
std::string quotedForMessage(std::string_view text, size_t max_chars = 60);

}  // namespace io
}  // namespace evidential_slam
