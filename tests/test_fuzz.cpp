// Every input a fuzz harness found a fault with, kept under tests/fuzz/<harness>/ after the fix,
// run through the same harness body (fuzz/harness.h): each must now pass every check the harness
// makes, ending in the entry point's clean error where it is malformed (docs/fuzzing.md).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "harness.h"

namespace remora {
namespace {

namespace fs = std::filesystem;

TEST(Fuzz, KeptInputsPassTheirHarness) {
  std::size_t inputs = 0;
  for (const auto& harness : fs::directory_iterator(REMORA_FUZZ_KEPT)) {
    if (!harness.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(harness.path())) {
      std::ifstream in(file.path(), std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      try {
        fuzz::run_harness(harness.path().filename().string(), bytes.str());
      } catch (const std::exception& e) {
        ADD_FAILURE() << file.path() << ": " << e.what();
      }
      ++inputs;
    }
  }
  EXPECT_GE(inputs, 1u);
}

} // namespace
} // namespace remora
