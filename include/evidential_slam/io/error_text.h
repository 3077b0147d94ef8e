// Error text fit for a user's terminal: one line, printable, short. Exception texts from MRPT carry
// a banner, a location and a call stack; names and lines read from a file may hold any byte.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace evidential_slam {
namespace io {

// The message of an exception text on one line: its first line that says something (for MRPT's
// texts, the "Message:" part, or the "Location:" part when the message is empty; never the banner
// or the call stack); whitespace runs squeezed to one space, bytes outside printable ASCII shown as
// '?', cut to `max_chars` ("..." marks the cut). "(no message)" when nothing is left.
std::string oneLineMessage(const std::string& what, size_t max_chars = 160);

// `text` (a name or a line read from a file) in single quotes for a one-line message: printable
// ASCII as is, other bytes as \xNN, cut to `max_chars` of the original ("..." marks the cut).
std::string quotedForMessage(std::string_view text, size_t max_chars = 60);
// A file's path for a message: quotedForMessage with room for a whole path.
inline std::string quotedPath(std::string_view path) { return quotedForMessage(path, 400); }

}  // namespace io
}  // namespace evidential_slam
