// One-line error text. See error_text.h.
#include "evidential_slam/io/error_text.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace evidential_slam {
namespace io {
namespace {

bool printable(unsigned char c) { return c >= 0x20 && c < 0x7f; }

}  // namespace

std::string oneLineMessage(const std::string& what, size_t max_chars) {
  // The first line that says something: not a "==== MRPT exception ====" banner, not an empty
  // "Message:" (MRPT then puts the wrapped exception's text under "Location:"), and nothing from
  // the call stack on.
  std::string line;
  size_t begin = 0;
  while (begin < what.size()) {
    const size_t end = std::min(what.find('\n', begin), what.size());
    std::string candidate = what.substr(begin, end - begin);
    begin = end + 1;
    const size_t first = candidate.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    candidate = candidate.substr(first);
    if (candidate.rfind("Call stack", 0) == 0) break;
    if (candidate.rfind("====", 0) == 0) continue;
    for (const char* label : {"Message:", "Location:"}) {
      if (candidate.rfind(label, 0) == 0) candidate = candidate.substr(std::strlen(label));
    }
    if (candidate.find_first_not_of(" \t\r") == std::string::npos) continue;
    line = candidate;
    break;
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
