// libFuzzer entry of one reader's harness (harness.h); REMORA_FUZZ_VARIANT (a ReaderVariant) is
// set per executable by fuzz/CMakeLists.txt, which builds one per reader from this file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  remora::fuzz::run_reader(remora::fuzz::ReaderVariant::REMORA_FUZZ_VARIANT,
                           std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
