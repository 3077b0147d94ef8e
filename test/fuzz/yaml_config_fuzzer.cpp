// libFuzzer target for the parameter-file loader (config/*.yaml; --config, --preset): the bytes as
// the text of a file (readParameterText), its entries applied to the defaults
// (applyParameterEntries) as the offline runner does. Refusals give a one-line printable error;
// accepted files leave no entry behind an error.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/parameter_file.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace io = evidential_slam::io;
  using evidential_slam::fuzz::checkErrorLine;
  using evidential_slam::fuzz::die;
  const std::string text(reinterpret_cast<const char*>(data), size);

  std::vector<std::pair<std::string, std::string>> entries;
  std::string error;
  if (!io::readParameterText(text, "fuzz.yaml", &entries, &error)) {
    if (!entries.empty()) die("entries left after an error", "");
    checkErrorLine(error);
    return 0;
  }
  evidential_slam::Parameters params;
  std::vector<std::string> ignored;
  if (!io::applyParameterEntries(entries, "fuzz.yaml", &params, &ignored, &error)) {
    checkErrorLine(error);
    return 0;
  }
  // Every value was in its row's range; what is left are the checks across rows.
  std::string why;
  if (!params.isValid(&why)) checkErrorLine(why);
  return 0;
}
