// fuzz/fuzz_problem_file.cpp: libFuzzer target for the problem-file reader. The input is the text
// of a problem file; fesd::fuzz::problem_file_finding (fuzz/oracles.hpp) says what it must do.
// Seed corpus: examples/*.toml. docs/fuzzing.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fuzz/oracles.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string finding =
      fesd::fuzz::problem_file_finding(std::string_view(reinterpret_cast<const char*>(data), size));
  if (!finding.empty()) {
    std::fprintf(stderr, "fuzz_problem_file: %s\n", finding.c_str());
    std::abort();
  }
  return 0;
}
