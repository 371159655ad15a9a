// libFuzzer entry of the EDIT.json parser's harness (harness.h).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  remora::fuzz::run_edit_request(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
