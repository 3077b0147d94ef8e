// One-line error text. See error_text.h.
#include "evidential_slam/io/error_text.h"

#include <algorithm>
#include <cstdio>

namespace evidential_slam {
namespace io {
namespace {

bool printable(unsigned char c) { return c >= 0x20 && c < 0x7f; }

}  // namespace

std::string oneLineMessage(const std::string& what, size_t max_chars) {
  std::string text = what;
  const size_t message = text.find("Message:");
  if (message != std::string::npos) {
    text = text.substr(message + 8);
    for (const char* cut :
         {"\nLocation:", "Location:", "\nCall stack", "\n=====", "\nOriginal exception:"}) {
      const size_t at = text.find(cut);
      if (at != std::string::npos) text.resize(at);
    }
  }
  // The first line with something on it.
  size_t begin = 0;
  std::string line;
  while (begin <= text.size()) {
    const size_t end = std::min(text.find('\n', begin), text.size());
    line = text.substr(begin, end - begin);
    if (line.find_first_not_of(" \t\r") != std::string::npos) break;
    line.clear();
    begin = end + 1;
  }
  std::string out;
  bool space = false;
  for (unsigned char c : line) {
    if (c == ' ' || c == '\t' || c == '\r') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += printable(c) ? static_cast<char>(c) : '?';
  }
  if (out.empty()) return "(no message)";
  if (out.size() > max_chars) out = out.substr(0, max_chars > 3 ? max_chars - 3 : 0) + "...";
  return out;
}

std::string quotedForMessage(std::string_view text, size_t max_chars) {
  std::string out = "'";
  const size_t n = std::min(text.size(), max_chars);
  for (size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (printable(c) && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  if (text.size() > max_chars) out += "...";
  return out + "'";
}

}  // namespace io
}  // namespace evidential_slam
