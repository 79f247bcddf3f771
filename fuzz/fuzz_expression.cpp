// fuzz/fuzz_expression.cpp: libFuzzer target for the expression language
// (src/model/expression.hpp): parse, evaluate with every scalar type (values, first and second
// derivatives, sparsity). The input is one expression over the symbols x, y, z, t, p;
// fesd::fuzz::expression_finding (fuzz/oracles.hpp) says what it must do. Seed corpus: the
// expressions of examples/*.toml (fuzz/extract_expressions.py). docs/fuzzing.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fuzz/oracles.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string finding =
      fesd::fuzz::expression_finding(std::string_view(reinterpret_cast<const char*>(data), size));
  if (!finding.empty()) {
    std::fprintf(stderr, "fuzz_expression: %s\n", finding.c_str());
    std::abort();
  }
  return 0;
}
