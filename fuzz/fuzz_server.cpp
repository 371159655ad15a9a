// libFuzzer entry of the server handlers' harness (harness.h).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  remora::fuzz::run_server_script(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
