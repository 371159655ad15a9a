// libFuzzer entry of one reader; REMORA_FUZZ_VARIANT (a ReaderVariant) is set per executable by
// fuzz/CMakeLists.txt, which builds one harness per reader from this file and read_harness.cpp.
#include <cstddef>
#include <cstdint>

#include "read_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return remora::fuzz::run_reader(remora::fuzz::ReaderVariant::REMORA_FUZZ_VARIANT, data, size);
}
