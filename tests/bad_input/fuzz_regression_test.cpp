// tests/bad_input/fuzz_regression_test.cpp: every input the fuzzers (fuzz/, docs/fuzzing.md) or
// the issues found is kept in tests/bad_input/fuzz/<target>/ and must now be handled cleanly: a
// fesd::Error with a short message or success, and a simulation file that loads also builds
// (fuzz/oracles.hpp, the fuzz targets' own checks). A crash here is a regression.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/oracles.hpp"

namespace {

const std::string kDir = std::string(FESD_SOURCE_DIR) + "/tests/bad_input/fuzz/";

std::vector<std::string> inputs(const std::string& target) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(kDir + target))
    if (entry.is_regular_file() && entry.path().filename() != "README.md")
      names.push_back(target + "/" + entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read(const std::string& name) {
  std::ifstream in(kDir + name, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param.substr(info.param.find('/') + 1);
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

class FuzzProblemFile : public ::testing::TestWithParam<std::string> {};
TEST_P(FuzzProblemFile, IsHandledCleanly) {
  EXPECT_EQ(fesd::fuzz::problem_file_finding(read(GetParam())), "");
}
INSTANTIATE_TEST_SUITE_P(Reproducers, FuzzProblemFile, ::testing::ValuesIn(inputs("problem_file")),
                         test_name);

class FuzzExpression : public ::testing::TestWithParam<std::string> {};
TEST_P(FuzzExpression, IsHandledCleanly) {
  EXPECT_EQ(fesd::fuzz::expression_finding(read(GetParam())), "");
}
INSTANTIATE_TEST_SUITE_P(Reproducers, FuzzExpression, ::testing::ValuesIn(inputs("expression")),
                         test_name);

TEST(FuzzReproducers, ArePresent) {
  // Guards against the parameterised tests silently running nothing.
  EXPECT_GE(inputs("problem_file").size(), 3U);
  EXPECT_GE(inputs("expression").size(), 3U);
}

}  // namespace
